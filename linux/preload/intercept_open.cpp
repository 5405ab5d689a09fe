// Replaced C library functions that create and destroy descriptors: the open family,
// fopen, close (and close_range/closefrom), dup, dup2, dup3 and fcntl(F_DUPFD*).
// Paths that are not emulated go to the C library untouched.
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <sys/mman.h>
#include <sys/syscall.h>
#include <unistd.h>
#include <linux/close_range.h>

#include <cstring>
#include <string>

#include "linux/log.hpp"
#include "linux/preload/node_path.hpp"
#include "linux/preload/check_exit.hpp"
#include "linux/preload/real.hpp"
#include "linux/preload/pwm_sysfs.hpp"
#include "linux/preload/state.hpp"
#include "linux/preload/sysfs.hpp"
#include "linux/preload/virtual_time.hpp"

using namespace l6470emu;
using namespace l6470emu::preload;

namespace {

int set_errno(long negative_errno) {
  errno = static_cast<int>(-negative_errno);
  return -1;
}

// A sysfs attribute: a memfd holding its contents, read position 0.
int open_virtual_file(const VirtualPath& v, int flags) {
  if ((flags & O_ACCMODE) != O_RDONLY) return set_errno(-EACCES);
  const int fd = memfd_create("l6470emu-sysfs", (flags & O_CLOEXEC) ? MFD_CLOEXEC : 0);
  if (fd < 0) return -1;
  raw_write_all(fd, v.content.data(), v.content.size());
  lseek(fd, 0, SEEK_SET);
  return fd;
}

// Returns true when `path` (relative paths from `dirfd`) is ours (result in `fd`, errno set on
// failure). The kernel's walk decides: any spelling of a node's path opens it, a path that goes
// on past a node is ENOTDIR.
bool try_open(int dirfd, const char* path, int flags, int& fd) {
  if (inside() || !path || !active()) return false;
  std::string absolute;
  if (path[0] != '/') {
    // Relative: one getcwd (or readlink of the directory's descriptor) for what may be under /dev.
    Guard guard;
    absolute = absolute_path(dirfd, path);
    if (absolute.empty()) return false;
    path = absolute.c_str();
  }
  if (!may_be_device_path(path)) return false;
  Guard guard;
  try {
    int node = -1;
    const NodeWalk walk = walk_to_node(path, node);
    if (walk == NodeWalk::through_node) {
      fd = set_errno(-ENOTDIR);
      return true;
    }
    if (walk == NodeWalk::not_ours) {
      note_missing_node(path);  // a /dev/spidev or gpiochip path the board lacks: said once
      if (std::strncmp(path, "/sys/", 5) != 0) return false;
      if (open_pwm_file(path, flags, fd)) return true;
      const VirtualPath v = lookup_virtual(path, true);
      if (v.type == VirtualPath::Type::file) {
        fd = open_virtual_file(v, flags);
        return true;
      }
      return false;
    }
    if (flags & O_DIRECTORY) {
      fd = set_errno(-ENOTDIR);
      return true;
    }
    if ((flags & (O_CREAT | O_EXCL)) == (O_CREAT | O_EXCL)) {
      fd = set_errno(-EEXIST);
      return true;
    }
    Backend* b = backend();
    const NewFile f = b->open(static_cast<std::size_t>(node), (flags & O_CLOEXEC) != 0);
    if (f.result < 0) {
      fd = set_errno(f.result);
      return true;
    }
    if (flags & O_NONBLOCK) real::fcntl(f.fd, F_SETFL, O_NONBLOCK);
    auto* e = new FdEntry;
    e->handle = f.handle;
    e->kind = f.kind;
    e->node = static_cast<std::uint32_t>(node);
    e->access = static_cast<std::uint32_t>(flags & O_ACCMODE);
    fd_store(f.fd, e);
    fd = f.fd;
    return true;
  } catch (...) {
    fd = set_errno(-ENOMEM);
    return true;
  }
}

mode_t mode_arg(int flags, va_list ap) {
  return (flags & O_CREAT) || (flags & O_TMPFILE) == O_TMPFILE ? static_cast<mode_t>(va_arg(ap, int)) : 0;
}

// After a real close: drop our entry (and tell the board when no copy is left here), and a
// virtual timerfd's timer.
void forget_fd(int fd) {
  if (FdEntry* e = fd_take(fd)) fd_release(e);
  forget_virtual_timerfd(fd);
  forget_pwm_fd(fd);
}

// A descriptor the C library just handed out must not look emulated (stale entry).
int fresh(int fd) {
  if (fd >= 0 && fd_entry(fd) && !in_vfork_child()) forget_fd(fd);
  if (fd >= 0 && pwm_fds_exist() && !in_vfork_child()) forget_pwm_fd(fd);
  return fd;
}

int dup_entry(int from, int to) {
  if (to < 0) return to;
  if ((fd_entry(from) || fd_entry(to)) && in_vfork_child()) return to;  // the parent's table
  if (FdEntry* e = fd_entry(from)) {
    e->refs.fetch_add(1, std::memory_order_acq_rel);
    fd_store(to, e);
  } else {
    fresh(to);
    if (pwm_fds_exist() && !in_vfork_child()) dup_pwm_fd(from, to);
  }
  return to;
}

}  // namespace

extern "C" {

__attribute__((visibility("default"))) int open(const char* path, int flags, ...) {
  va_list ap;
  va_start(ap, flags);
  const mode_t mode = mode_arg(flags, ap);
  va_end(ap);
  int fd;
  if (try_open(AT_FDCWD, path, flags, fd)) return fd;
  return fresh(real::open(path, flags, mode));
}

__attribute__((visibility("default"))) int open64(const char* path, int flags, ...) {
  va_list ap;
  va_start(ap, flags);
  const mode_t mode = mode_arg(flags, ap);
  va_end(ap);
  int fd;
  if (try_open(AT_FDCWD, path, flags, fd)) return fd;
  return fresh(real::open(path, flags, mode));
}

__attribute__((visibility("default"))) int __open_2(const char* path, int flags) {
  int fd;
  if (try_open(AT_FDCWD, path, flags, fd)) return fd;
  return fresh(real::open(path, flags, 0));
}

__attribute__((visibility("default"))) int __open64_2(const char* path, int flags) {
  int fd;
  if (try_open(AT_FDCWD, path, flags, fd)) return fd;
  return fresh(real::open(path, flags, 0));
}

__attribute__((visibility("default"))) int openat(int dirfd, const char* path, int flags, ...) {
  va_list ap;
  va_start(ap, flags);
  const mode_t mode = mode_arg(flags, ap);
  va_end(ap);
  int fd;
  if (try_open(dirfd, path, flags, fd)) return fd;
  return fresh(real::openat(dirfd, path, flags, mode));
}

__attribute__((visibility("default"))) int openat64(int dirfd, const char* path, int flags, ...) {
  va_list ap;
  va_start(ap, flags);
  const mode_t mode = mode_arg(flags, ap);
  va_end(ap);
  int fd;
  if (try_open(dirfd, path, flags, fd)) return fd;
  return fresh(real::openat(dirfd, path, flags, mode));
}

__attribute__((visibility("default"))) int __openat_2(int dirfd, const char* path, int flags) {
  int fd;
  if (try_open(dirfd, path, flags, fd)) return fd;
  return fresh(real::openat(dirfd, path, flags, 0));
}

__attribute__((visibility("default"))) int __openat64_2(int dirfd, const char* path, int flags) {
  int fd;
  if (try_open(dirfd, path, flags, fd)) return fd;
  return fresh(real::openat(dirfd, path, flags, 0));
}

static FILE* fopen_impl(const char* path, const char* mode) {
  if (!inside() && path && mode && active()) {
    int flags = O_RDONLY;
    if (mode[0] == 'w' || mode[0] == 'a') flags = O_WRONLY;
    if (std::strchr(mode, '+')) flags = O_RDWR;
    if (std::strchr(mode, 'e')) flags |= O_CLOEXEC;
    int fd;
    if (try_open(AT_FDCWD, path, flags, fd)) {
      if (fd < 0) return nullptr;
      FILE* f = pwm_fds_exist() ? pwm_stream(fd, mode) : nullptr;
      if (!f) f = fdopen(fd, mode);
      if (!f) {
        const int e = errno;
        close(fd);
        errno = e;
      }
      return f;
    }
  }
  return real::fopen(path, mode);
}

__attribute__((visibility("default"))) FILE* fopen(const char* path, const char* mode) { return fopen_impl(path, mode); }
__attribute__((visibility("default"))) FILE* fopen64(const char* path, const char* mode) { return fopen_impl(path, mode); }

__attribute__((visibility("default"))) int close(int fd) {
  if (protected_fd_is(fd)) {  // the host closes the daemon connection (closefrom-style clean-up)
    if (in_vfork_child()) return real::close(fd);  // its own descriptor; the memory is the parent's
    real_close_protected(fd);
    return 0;
  }
  FdEntry* e = fd_entry(fd) && !in_vfork_child() ? fd_take(fd) : nullptr;
  const long flushed = pwm_fds_exist() && !in_vfork_child() ? flush_pwm_fd(fd) : 0;
  const int r = real::close(fd);
  forget_virtual_timerfd(fd);
  if (pwm_fds_exist() && !in_vfork_child()) forget_pwm_fd(fd);
  if (r == 0 && flushed < 0) {  // a sysfs write refused: the kernel would have said so at write()
    errno = static_cast<int>(-flushed);
    return -1;
  }
  if (e) {
    const int saved = errno;
    fd_release(e);
    errno = saved;
  }
  return r;
}

__attribute__((visibility("default"))) int close_range(unsigned first, unsigned last, int flags) {
  const int r = static_cast<int>(syscall(SYS_close_range, first, last, flags));
  if (r == 0 && !(flags & CLOSE_RANGE_CLOEXEC) && !in_vfork_child()) {
    const int saved = errno;
    for (unsigned fd = first; fd <= last && fd < (1u << 16); ++fd) {
      if (protected_fd_is(static_cast<int>(fd))) real_close_protected(static_cast<int>(fd));
      forget_fd(static_cast<int>(fd));
    }
    errno = saved;
  }
  return r;
}

__attribute__((visibility("default"))) void closefrom(int lowfd) {
  if (lowfd < 0) lowfd = 0;
  close_range(static_cast<unsigned>(lowfd), ~0u, 0);
}

__attribute__((visibility("default"))) int dup(int fd) { return dup_entry(fd, real::dup(fd)); }

__attribute__((visibility("default"))) int dup2(int fd, int fd2) {
  if (fd == fd2) return real::dup2(fd, fd2);
  FdEntry* old = fd_entry(fd2) && !in_vfork_child() ? fd_take(fd2) : nullptr;
  if (pwm_fds_exist() && !in_vfork_child()) flush_pwm_fd(fd2);
  const int r = real::dup2(fd, fd2);
  if (r >= 0) forget_virtual_timerfd(fd2);
  if (old) {
    if (r < 0)
      fd_store(fd2, old);
    else
      fd_release(old);
  }
  return r < 0 ? r : dup_entry(fd, r);
}

__attribute__((visibility("default"))) int dup3(int fd, int fd2, int flags) {
  FdEntry* old = (fd != fd2 && fd_entry(fd2) && !in_vfork_child()) ? fd_take(fd2) : nullptr;
  if (fd != fd2 && pwm_fds_exist() && !in_vfork_child()) flush_pwm_fd(fd2);
  const int r = real::dup3(fd, fd2, flags);
  if (r >= 0) forget_virtual_timerfd(fd2);
  if (old) {
    if (r < 0)
      fd_store(fd2, old);
    else
      fd_release(old);
  }
  return r < 0 ? r : dup_entry(fd, r);
}

static int fcntl_impl(int fd, int cmd, va_list ap) {
  // Every fcntl command takes at most one argument, an int, a long or a pointer.
  const long arg = va_arg(ap, long);
  const int r = real::fcntl(fd, cmd, arg);
  if ((cmd == F_DUPFD || cmd == F_DUPFD_CLOEXEC) && r >= 0) return dup_entry(fd, r);
  // The access mode is the open's, as the kernel keeps it in the file (not the descriptor's behind it).
  if (cmd == F_GETFL && r >= 0)
    if (const FdEntry* e = fd_entry(fd)) return (r & ~O_ACCMODE) | static_cast<int>(e->access);
  return r;
}

__attribute__((visibility("default"))) int fcntl(int fd, int cmd, ...) {
  va_list ap;
  va_start(ap, cmd);
  const int r = fcntl_impl(fd, cmd, ap);
  va_end(ap);
  return r;
}

__attribute__((visibility("default"))) int fcntl64(int fd, int cmd, ...) {
  va_list ap;
  va_start(ap, cmd);
  const int r = fcntl_impl(fd, cmd, ap);
  va_end(ap);
  return r;
}

}  // extern "C"
