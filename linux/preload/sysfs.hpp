// The file-system view libgpiod and friends check before trusting a device node: the
// /dev nodes themselves (character devices) and the sysfs entries that vouch for them
// (/sys/bus/gpio/devices/gpiochipN/{dev,subsystem,uevent}, /sys/dev/char/MAJ:MIN,
// /sys/class/spidev/spidevB.C). Everything is derived from the device-node catalogue; and
// /sys/class/pwm, from the board's chains (pwm_sysfs.hpp).
#pragma once

#include <sys/stat.h>

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace l6470emu::preload {

/// A path the preload answers for.
struct VirtualPath {
  /// not_directory: the path goes on past an emulated node (stat and friends fail with ENOTDIR).
  enum class Type { none, char_device, directory, file, symlink, not_directory } type = Type::none;
  std::string content;  ///< file contents, or the symlink target
  unsigned major = 0, minor = 0;
  int node = -1;        ///< device node index for char devices
  unsigned mode = 0;    ///< a file's permission bits (0: 0444)
};

/// What `path` is in the emulated view (Type::none: not ours, ask the real file system).
/// With `follow`, symbolic links are followed (stat); without, a link is reported (lstat).
VirtualPath lookup_virtual(std::string_view path, bool follow);

/// realpath() of a path inside the emulated view ("" when not ours).
std::string virtual_realpath(std::string_view path);

/// Entries the emulated view adds to directory `dir` (name, d_type); empty for most directories.
std::vector<std::pair<std::string, unsigned char>> virtual_dir_entries(std::string_view dir);

/// A struct stat for a virtual path.
void fill_stat(const VirtualPath& v, struct stat* st);

}  // namespace l6470emu::preload
