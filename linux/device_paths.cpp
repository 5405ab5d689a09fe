// What exists at a chain's path=: stat, and the kernel's name of a character device from sysfs.
#include "linux/device_paths.hpp"

#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace l6470emu {

std::string existing_non_spidev(const std::string& path) {
  constexpr unsigned kSpidevDriverMajor = 153;  // SPIDEV_MAJOR, drivers/spi/spidev.c
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0)
    return errno == ENOENT ? "" : std::string("a path that cannot be looked at (") + std::strerror(errno) + ")";
  const std::string dev = std::to_string(major(st.st_rdev)) + ":" + std::to_string(minor(st.st_rdev));
  if (S_ISCHR(st.st_mode)) {
    if (major(st.st_rdev) == kSpidevDriverMajor) return "";
    // The kernel's name of the device: the last part of /sys/dev/char/MAJ:MIN's target.
    char target[512];
    const ssize_t n = ::readlink(("/sys/dev/char/" + dev).c_str(), target, sizeof target - 1);
    std::string name = n > 0 ? std::string(target, static_cast<std::size_t>(n)) : "";
    name = name.substr(name.rfind('/') + 1);
    if (name.rfind("spidev", 0) == 0) return "";
    return "an existing character device (" + dev + (name.empty() ? "" : ", " + quoted_text(name)) + ") of another driver";
  }
  if (S_ISBLK(st.st_mode)) return "an existing block device (" + dev + ")";
  if (S_ISDIR(st.st_mode)) return "an existing directory";
  if (S_ISREG(st.st_mode)) return "an existing regular file";
  return "an existing file that is not a device node";
}

std::string check_device_paths(const BoardConfig& config, std::string_view origin) {
  for (std::size_t i = 0; i < config.chains.size(); ++i) {
    const ChainConfig& c = config.chains[i];
    if (const std::string why = existing_non_spidev(c.path); !why.empty())
      return "l6470emu: config " + shown_text(origin, 200) + ": chain " + std::to_string(i + 1) + " (bus=" +
             std::to_string(c.bus) + " cs=" + std::to_string(c.cs) + "): path " + quoted_text(c.path) + " is " + why +
             ", not a spidev node: the emulator would take it over in host programs (write a path that does not "
             "exist, e.g. path=/dev/spidev9.0, or leave path= out)";
  }
  return "";
}

}  // namespace l6470emu
