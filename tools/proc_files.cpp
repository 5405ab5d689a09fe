// is_pid_name and read_small_file.
#include "tools/proc_files.hpp"

#include <fcntl.h>
#include <unistd.h>

namespace l6470emu {

bool is_pid_name(const char* s) {
  if (!*s) return false;
  for (; *s; ++s)
    if (*s < '0' || *s > '9') return false;
  return true;
}

std::string read_small_file(const std::string& path, std::size_t limit) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return {};
  std::string text;
  char buf[4096];
  for (ssize_t n; text.size() < limit && (n = read(fd, buf, sizeof buf)) > 0;) text.append(buf, static_cast<std::size_t>(n));
  close(fd);
  if (text.size() > limit) text.resize(limit);
  return text;
}

}  // namespace l6470emu
