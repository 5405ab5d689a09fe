// Replaced C library functions that look at paths and descriptors without opening them:
// the stat family (including the pre-2.33 __xstat entry points and statx), access,
// realpath, readlink. Emulated /dev nodes are character devices; the sysfs entries that
// vouch for them exist. Everything else goes to the C library.
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include "linux/preload/node_path.hpp"
#include "linux/preload/real.hpp"
#include "linux/preload/state.hpp"
#include "linux/preload/sysfs.hpp"

using namespace l6470emu;
using namespace l6470emu::preload;

namespace {

bool candidate(const char* path) { return !inside() && active() && may_be_device_path(path); }

// The C library declares the path arguments nonnull; programs pass NULL all the same (the kernel
// answers EFAULT). Tested here, not in the functions themselves, where compilers would warn.
bool absolute(const char* path) { return path && path[0] == '/'; }
bool empty_path(const char* path) { return path && path[0] == '\0'; }

// 1 when `path` is ours (`st` filled), -1 when it is ours and fails (errno set: a path that goes
// on past a node), 0 when it is not ours.
int virtual_stat(const char* path, struct stat* st, bool follow) {
  if (!candidate(path)) return 0;
  Guard guard;
  try {
    const VirtualPath v = lookup_virtual(path, follow);
    if (v.type == VirtualPath::Type::none) return 0;
    if (v.type == VirtualPath::Type::not_directory) {
      errno = ENOTDIR;
      return -1;
    }
    fill_stat(v, st);
    return 1;
  } catch (...) {
    return 0;
  }
}

// fstat of an emulated spidev/gpiochip descriptor; line requests stay anonymous (real fstat).
bool virtual_fstat(int fd, struct stat* st) {
  if (inside()) return false;
  FdEntry* e = fd_entry(fd);
  if (!e || (e->kind != HandleKind::spidev && e->kind != HandleKind::gpiochip)) return false;
  Guard guard;
  const auto& ns = nodes();
  if (e->node >= ns.size()) return false;
  VirtualPath v;
  v.type = VirtualPath::Type::char_device;
  v.major = ns[e->node].major;
  v.minor = ns[e->node].minor;
  v.node = static_cast<int>(e->node);
  fill_stat(v, st);
  return true;
}

void to_statx(const struct stat& st, struct statx* sx) {
  memset(sx, 0, sizeof *sx);
  sx->stx_mask = STATX_BASIC_STATS;
  sx->stx_blksize = static_cast<std::uint32_t>(st.st_blksize);
  sx->stx_nlink = static_cast<std::uint32_t>(st.st_nlink);
  sx->stx_uid = st.st_uid;
  sx->stx_gid = st.st_gid;
  sx->stx_mode = static_cast<std::uint16_t>(st.st_mode);
  sx->stx_ino = st.st_ino;
  sx->stx_size = static_cast<std::uint64_t>(st.st_size);
  sx->stx_atime = {st.st_atim.tv_sec, static_cast<std::uint32_t>(st.st_atim.tv_nsec), 0};
  sx->stx_mtime = {st.st_mtim.tv_sec, static_cast<std::uint32_t>(st.st_mtim.tv_nsec), 0};
  sx->stx_ctime = {st.st_ctim.tv_sec, static_cast<std::uint32_t>(st.st_ctim.tv_nsec), 0};
  sx->stx_rdev_major = major(st.st_rdev);
  sx->stx_rdev_minor = minor(st.st_rdev);
  sx->stx_dev_major = major(st.st_dev);
  sx->stx_dev_minor = minor(st.st_dev);
}

int do_fstatat(int dirfd, const char* path, struct stat* st, int flags) {
  if (empty_path(path) && (flags & AT_EMPTY_PATH)) {
    if (virtual_fstat(dirfd, st)) return 0;
  } else if (absolute(path)) {
    if (const int r = virtual_stat(path, st, !(flags & AT_SYMLINK_NOFOLLOW)); r != 0) return r > 0 ? 0 : -1;
  }
  return real::fstatat(dirfd, path, st, flags);
}

char* do_realpath(const char* path, char* resolved) {
  if (candidate(path)) {
    Guard guard;
    try {
      if (lookup_virtual(path, true).type == VirtualPath::Type::not_directory) {
        errno = ENOTDIR;
        return nullptr;
      }
      const std::string r = virtual_realpath(path);
      if (!r.empty()) {
        if (r.size() >= PATH_MAX) {
          errno = ENAMETOOLONG;
          return nullptr;
        }
        char* out = resolved ? resolved : static_cast<char*>(malloc(PATH_MAX));
        if (!out) {
          errno = ENOMEM;
          return nullptr;
        }
        memcpy(out, r.c_str(), r.size() + 1);
        return out;
      }
    } catch (...) {
    }
  }
  return real::realpath(path, resolved);
}

// readlink of one of our symlinks: >= 0 length, -1 with errno, -2 = not ours.
ssize_t do_readlink(const char* path, char* buf, size_t n) {
  if (!candidate(path)) return -2;
  Guard guard;
  try {
    const VirtualPath v = lookup_virtual(path, false);
    if (v.type == VirtualPath::Type::none) return -2;
    if (v.type == VirtualPath::Type::not_directory) {
      errno = ENOTDIR;
      return -1;
    }
    if (v.type != VirtualPath::Type::symlink) {
      errno = EINVAL;
      return -1;
    }
    const size_t len = v.content.size() < n ? v.content.size() : n;
    memcpy(buf, v.content.data(), len);
    return static_cast<ssize_t>(len);
  } catch (...) {
    return -2;
  }
}

int do_access(const char* path, int mode) {
  struct stat st;
  if (const int r = virtual_stat(path, &st, true); r <= 0) return r == 0 ? -2 : -1;
  if ((mode & X_OK) && !S_ISDIR(st.st_mode)) {
    errno = EACCES;
    return -1;
  }
  return 0;
}

}  // namespace

extern "C" {

#define L6470EMU_EXPORT __attribute__((visibility("default")))

L6470EMU_EXPORT int stat(const char* path, struct stat* st) noexcept {
  if (const int r = virtual_stat(path, st, true); r != 0) return r > 0 ? 0 : -1;
  return real::stat(path, st);
}
L6470EMU_EXPORT int stat64(const char* path, struct stat64* st) noexcept {
  return stat(path, reinterpret_cast<struct stat*>(st));
}
L6470EMU_EXPORT int lstat(const char* path, struct stat* st) noexcept {
  if (const int r = virtual_stat(path, st, false); r != 0) return r > 0 ? 0 : -1;
  return real::lstat(path, st);
}
L6470EMU_EXPORT int lstat64(const char* path, struct stat64* st) noexcept {
  return lstat(path, reinterpret_cast<struct stat*>(st));
}
L6470EMU_EXPORT int fstat(int fd, struct stat* st) noexcept {
  if (virtual_fstat(fd, st)) return 0;
  return real::fstat(fd, st);
}
L6470EMU_EXPORT int fstat64(int fd, struct stat64* st) noexcept { return fstat(fd, reinterpret_cast<struct stat*>(st)); }
L6470EMU_EXPORT int fstatat(int dirfd, const char* path, struct stat* st, int flags) noexcept {
  return do_fstatat(dirfd, path, st, flags);
}
L6470EMU_EXPORT int fstatat64(int dirfd, const char* path, struct stat64* st, int flags) noexcept {
  return do_fstatat(dirfd, path, reinterpret_cast<struct stat*>(st), flags);
}
// glibc < 2.33 entry points (binaries built against an older glibc call these).
L6470EMU_EXPORT int __xstat(int, const char* path, struct stat* st) { return stat(path, st); }
L6470EMU_EXPORT int __xstat64(int, const char* path, struct stat64* st) { return stat64(path, st); }
L6470EMU_EXPORT int __lxstat(int, const char* path, struct stat* st) { return lstat(path, st); }
L6470EMU_EXPORT int __lxstat64(int, const char* path, struct stat64* st) { return lstat64(path, st); }
L6470EMU_EXPORT int __fxstat(int, int fd, struct stat* st) { return fstat(fd, st); }
L6470EMU_EXPORT int __fxstat64(int, int fd, struct stat64* st) { return fstat64(fd, st); }
L6470EMU_EXPORT int __fxstatat(int, int dirfd, const char* path, struct stat* st, int flags) {
  return do_fstatat(dirfd, path, st, flags);
}
L6470EMU_EXPORT int __fxstatat64(int, int dirfd, const char* path, struct stat64* st, int flags) {
  return do_fstatat(dirfd, path, reinterpret_cast<struct stat*>(st), flags);
}

L6470EMU_EXPORT int statx(int dirfd, const char* path, int flags, unsigned mask, struct statx* buf) noexcept {
  struct stat st;
  if (empty_path(path) && (flags & AT_EMPTY_PATH)) {
    if (virtual_fstat(dirfd, &st)) {
      to_statx(st, buf);
      return 0;
    }
  } else if (absolute(path)) {
    if (const int r = virtual_stat(path, &st, !(flags & AT_SYMLINK_NOFOLLOW)); r != 0) {
      if (r < 0) return -1;
      to_statx(st, buf);
      return 0;
    }
  }
  return real::statx(dirfd, path, flags, mask, buf);
}

L6470EMU_EXPORT int access(const char* path, int mode) noexcept {
  const int r = do_access(path, mode);
  return r == -2 ? real::access(path, mode) : r;
}
L6470EMU_EXPORT int faccessat(int dirfd, const char* path, int mode, int flags) noexcept {
  if (absolute(path)) {
    const int r = do_access(path, mode);
    if (r != -2) return r;
  }
  return real::faccessat(dirfd, path, mode, flags);
}

L6470EMU_EXPORT char* realpath(const char* path, char* resolved) noexcept { return do_realpath(path, resolved); }
L6470EMU_EXPORT char* __realpath_chk(const char* path, char* resolved, size_t) { return do_realpath(path, resolved); }
L6470EMU_EXPORT char* canonicalize_file_name(const char* path) noexcept { return do_realpath(path, nullptr); }

L6470EMU_EXPORT ssize_t readlink(const char* path, char* buf, size_t n) noexcept {
  const ssize_t r = do_readlink(path, buf, n);
  return r == -2 ? real::readlink(path, buf, n) : r;
}
L6470EMU_EXPORT ssize_t readlinkat(int dirfd, const char* path, char* buf, size_t n) noexcept {
  if (absolute(path)) {
    const ssize_t r = do_readlink(path, buf, n);
    if (r != -2) return r;
  }
  return real::readlinkat(dirfd, path, buf, n);
}

}  // extern "C"
