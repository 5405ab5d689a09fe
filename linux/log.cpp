// Diagnostic log over raw system calls.
#include "linux/log.hpp"

#include <fcntl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>

namespace l6470emu {

bool raw_write_all(int fd, const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const long n = syscall(SYS_write, fd, p, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

DiagnosticLog::DiagnosticLog(const std::string& where) {
  if (where == "off" || where.empty()) return;
  if (where == "stderr") {
    fd_ = 2;
    return;
  }
  const int saved = errno;
  fd_ = static_cast<int>(syscall(SYS_openat, AT_FDCWD, where.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644));
  errno = saved;
  owned_ = fd_ >= 0;
  if (fd_ < 0) fd_ = 2;  // fall back to stderr rather than lose diagnostics
}

DiagnosticLog::~DiagnosticLog() {
  if (owned_) syscall(SYS_close, fd_);
}

void DiagnosticLog::line(std::string_view text) {
  if (fd_ < 0) return;
  std::string s;
  s.reserve(text.size() + 12);
  s += "l6470emu: ";
  s += text;
  s += '\n';
  const int saved = errno;
  std::lock_guard lock(m_);
  raw_write_all(fd_, s.data(), s.size());
  errno = saved;
}

}  // namespace l6470emu
