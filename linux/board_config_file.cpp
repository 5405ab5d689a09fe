// Reading a board description file: stat first (a device is refused before it is opened), then
// at most kMaxConfigBytes + 1 bytes, then board/board_config.cpp's parser.
#include "linux/board_config_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace l6470emu {

ParseResult load_board_config_file(const std::string& path) {
  const std::string where = "l6470emu: config file " + shown_text(path, 200) + ": ";
  auto failed = [&](const std::string& what) { return ParseResult{std::nullopt, {where + what}}; };
  // stat first: opening a device can block or have effects; a FIFO (a shell's <(...)) is fine.
  struct stat st{};
  if (::stat(path.c_str(), &st) != 0) return failed(std::string("cannot be read (") + std::strerror(errno) + ")");
  if (S_ISDIR(st.st_mode)) return failed("is a directory (give the board description file)");
  if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) return failed("is a device, not a board description file");
  if (!S_ISREG(st.st_mode) && !S_ISFIFO(st.st_mode)) return failed("is not a regular file");
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) return failed(std::string("cannot be read (") + std::strerror(errno) + ")");
  std::string text(kMaxConfigBytes + 1, '\0');
  std::size_t got = 0;
  while (got < text.size()) {
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int e = errno;
      ::close(fd);
      return failed(std::string("cannot be read (") + std::strerror(e) + ")");
    }
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  if (got > kMaxConfigBytes) return failed("longer than 1 MiB (a board description is a few lines: is this the right file?)");
  text.resize(got);
  return parse_board_config(text, path);
}

}  // namespace l6470emu
