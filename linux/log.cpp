// Diagnostic log over raw system calls; a log file that cannot be opened or written is reported
// once on stderr and stderr is used instead.
#include "linux/log.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <set>

#include "board/board_config.hpp"

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

namespace {

// Whether `key` is said for the first time in this process: several DiagnosticLogs of one
// process (the preload's own, its backend's) may name the same file.
bool first_report(const std::string& key) {
  static std::mutex m;
  static std::set<std::string>* reported = new std::set<std::string>();  // never freed: used until exit
  std::lock_guard lock(m);
  return reported->insert(key).second;
}

// Says once per process and file, on stderr, that a log file could not be opened.
void report_unopenable(const std::string& where, int error) {
  if (!first_report("open " + where)) return;
  const std::string why = error == ENXIO ? "a FIFO that nobody reads" : std::strerror(error);
  const std::string text = "l6470emu: log file " + quoted_text(where) + " cannot be opened (" + why +
                           "): diagnostics go to stderr\n";
  raw_write_all(2, text.data(), text.size());
}

// Says once per process and file, on stderr, that a log file refused a write.
void report_unwritable(const std::string& where, int error) {
  if (!first_report("write " + where)) return;
  const std::string why = error == EPIPE ? "a FIFO or socket whose reader went away" : std::strerror(error);
  const std::string text = "l6470emu: log file " + quoted_text(where) + " cannot be written (" + why +
                           "): diagnostics go to stderr from now on\n";
  raw_write_all(2, text.data(), text.size());
}

// raw_write_all() to a FIFO or socket with SIGPIPE held off: a reader that went away is an EPIPE
// for the log to report, never a signal that ends the host program. A SIGPIPE that was pending
// already (the program's own) stays pending.
bool write_all_without_sigpipe(int fd, const void* data, std::size_t size) {
  sigset_t pipe_only, old;
  sigemptyset(&pipe_only);
  sigaddset(&pipe_only, SIGPIPE);
  if (pthread_sigmask(SIG_BLOCK, &pipe_only, &old) != 0) return raw_write_all(fd, data, size);
  sigset_t pending;
  const bool was_pending = sigpending(&pending) == 0 && sigismember(&pending, SIGPIPE) == 1;
  const bool ok = raw_write_all(fd, data, size);
  const int error = errno;
  if (!ok && error == EPIPE && !was_pending) {
    const timespec zero{0, 0};
    while (sigtimedwait(&pipe_only, nullptr, &zero) < 0 && errno == EINTR) {
    }
  }
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  errno = error;
  return ok;
}

}  // namespace

DiagnosticLog::DiagnosticLog(const std::string& where) : where_(where) {
  if (where == "off" || where.empty()) return;
  if (where == "stderr") {
    fd_ = 2;
    return;
  }
  const int saved = errno;
  // O_NONBLOCK: a FIFO without a reader fails (ENXIO) instead of blocking the host program in
  // its start-up; cleared again once open. O_NOCTTY: a terminal named here is written to, not
  // made the process's controlling terminal.
  const int fd = static_cast<int>(syscall(SYS_openat, AT_FDCWD, where.c_str(),
                                          O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC | O_NOCTTY | O_NONBLOCK, 0644));
  if (fd >= 0) {
    const long flags = syscall(SYS_fcntl, fd, F_GETFL);
    if (flags >= 0) syscall(SYS_fcntl, fd, F_SETFL, flags & ~static_cast<long>(O_NONBLOCK));
    struct stat st {};
    pipe_ = syscall(SYS_fstat, fd, &st) == 0 && (S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode));
    fd_ = fd;
    owned_ = true;
  } else {
    open_error_ = errno;
    fd_ = 2;  // fall back to stderr rather than lose diagnostics, and say so once
    report_unopenable(where, open_error_);
  }
  errno = saved;
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
  if (owned_) {
    if (pipe_ ? write_all_without_sigpipe(fd_, s.data(), s.size()) : raw_write_all(fd_, s.data(), s.size())) {
      errno = saved;
      return;
    }
    // The file refused the line: say so once, and give the log to stderr (this line included).
    write_error_ = errno != 0 ? errno : EIO;
    syscall(SYS_close, fd_);
    owned_ = false;
    fd_ = 2;
    report_unwritable(where_, write_error_);
  }
  raw_write_all(fd_, s.data(), s.size());
  errno = saved;
}

}  // namespace l6470emu
