// Output checks: stat for what the path is, an open for whether it can be written.
#include "tools/output_check.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace l6470emu {

bool write_whole_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::trunc | std::ios::binary);
  out << text;
  out.close();
  return static_cast<bool>(out);
}

std::string absolute_path(const std::string& path) { return std::filesystem::absolute(path).lexically_normal().string(); }

std::string output_problem(const std::string& path, const std::vector<std::string>& inputs) {
  if (path.empty()) return "an empty path";
  struct stat st {};
  const bool exists = stat(path.c_str(), &st) == 0;
  if (exists && !S_ISREG(st.st_mode)) return "not a regular file";
  if (exists && (st.st_mode & 0222) == 0) return "a read-only file";
  for (const std::string& in : inputs) {
    struct stat is {};
    if (exists && !in.empty() && stat(in.c_str(), &is) == 0 && is.st_dev == st.st_dev && is.st_ino == st.st_ino)
      return "it is one of the inputs (" + in + "): an output never overwrites an input";
  }
  const int fd = open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC | O_NONBLOCK, 0644);
  if (fd < 0) return std::strerror(errno);
  close(fd);
  if (!exists) unlink(path.c_str());
  return "";
}

}  // namespace l6470emu
