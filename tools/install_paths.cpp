// The preload library's place at run time, build tree or installed prefix.
#include "tools/install_paths.hpp"

#include <unistd.h>

#include <cstdlib>
#include <sys/stat.h>

namespace l6470emu {
namespace {

bool is_file(const std::string& path) {
  struct stat st{};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string directory_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

/// "/usr/bin/../lib/l6470emu/x" -> "/usr/lib/l6470emu/x" (one level of "dir/.." per "..").
std::string without_dot_dots(std::string path) {
  for (std::size_t p; (p = path.find("/../")) != std::string::npos && p > 0;) {
    const std::size_t start = path.rfind('/', p - 1);
    if (start == std::string::npos) break;
    path.erase(start, p + 3 - start);
  }
  return path;
}

}  // namespace

std::string own_program_path() {
  char buf[4096];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
}

std::string preload_library_path(const std::string& exe) {
  if (const char* given = std::getenv("L6470EMU_PRELOAD"); given != nullptr && *given != '\0') return given;
  if (exe.empty()) return "";
  const std::string bin = directory_of(exe);
  if (const std::string beside = bin + "/libl6470emu-preload.so"; is_file(beside)) return beside;
  // L6470EMU_PRELOAD_FROM_BIN: the preload library relative to the installed program's directory
  // (cmake/install_dirs.cmake's layout, "../lib/l6470emu/libl6470emu-preload.so").
  if (const std::string installed = without_dot_dots(bin + "/" L6470EMU_PRELOAD_FROM_BIN); is_file(installed))
    return installed;
  return "";
}

}  // namespace l6470emu
