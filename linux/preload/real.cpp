// dlsym(RTLD_NEXT) look-ups of the replaced C library functions, cached after the first call.
#include "linux/preload/real.hpp"

#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <sys/ioctl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>

namespace l6470emu::real {
namespace {

template <typename F>
F resolve(std::atomic<void*>& slot, const char* name) {
  void* p = slot.load(std::memory_order_acquire);
  if (!p) {
    p = dlsym(RTLD_NEXT, name);
    slot.store(p, std::memory_order_release);
  }
  return reinterpret_cast<F>(p);
}

#define L6470EMU_REAL(ret, name, params)        \
  using name##_fn = ret(*) params;              \
  std::atomic<void*> name##_slot{nullptr};      \
  name##_fn get_##name() { return resolve<name##_fn>(name##_slot, #name); }

L6470EMU_REAL(int, open, (const char*, int, ...))
L6470EMU_REAL(int, openat, (int, const char*, int, ...))
L6470EMU_REAL(FILE*, fopen, (const char*, const char*))
L6470EMU_REAL(int, close, (int))
L6470EMU_REAL(int, dup, (int))
L6470EMU_REAL(int, dup2, (int, int))
L6470EMU_REAL(int, dup3, (int, int, int))
L6470EMU_REAL(int, fcntl, (int, int, ...))
L6470EMU_REAL(int, ioctl, (int, unsigned long, ...))
L6470EMU_REAL(ssize_t, read, (int, void*, size_t))
L6470EMU_REAL(ssize_t, write, (int, const void*, size_t))
L6470EMU_REAL(int, stat, (const char*, struct stat*))
L6470EMU_REAL(int, lstat, (const char*, struct stat*))
L6470EMU_REAL(int, fstat, (int, struct stat*))
L6470EMU_REAL(int, fstatat, (int, const char*, struct stat*, int))
L6470EMU_REAL(int, statx, (int, const char*, int, unsigned, struct ::statx*))
L6470EMU_REAL(int, access, (const char*, int))
L6470EMU_REAL(int, faccessat, (int, const char*, int, int))
L6470EMU_REAL(char*, realpath, (const char*, char*))
L6470EMU_REAL(ssize_t, readlink, (const char*, char*, size_t))
L6470EMU_REAL(ssize_t, readlinkat, (int, const char*, char*, size_t))
L6470EMU_REAL(DIR*, opendir, (const char*))
L6470EMU_REAL(struct dirent*, readdir, (DIR*))
L6470EMU_REAL(int, closedir, (DIR*))
L6470EMU_REAL(int, scandir, (const char*, struct dirent***, int (*)(const struct dirent*),
                             int (*)(const struct dirent**, const struct dirent**)))

}  // namespace

// Where dlsym finds nothing (a static or unusual libc), fall back to the system call.
int open(const char* path, int flags, mode_t mode) {
  if (auto f = get_open()) return f(path, flags, mode);
  return static_cast<int>(syscall(SYS_openat, AT_FDCWD, path, flags, mode));
}
int openat(int dirfd, const char* path, int flags, mode_t mode) {
  if (auto f = get_openat()) return f(dirfd, path, flags, mode);
  return static_cast<int>(syscall(SYS_openat, dirfd, path, flags, mode));
}
FILE* fopen(const char* path, const char* mode) { return get_fopen()(path, mode); }
int close(int fd) {
  if (auto f = get_close()) return f(fd);
  return static_cast<int>(syscall(SYS_close, fd));
}
int dup(int fd) { return get_dup()(fd); }
int dup2(int fd, int fd2) { return get_dup2()(fd, fd2); }
int dup3(int fd, int fd2, int flags) { return get_dup3()(fd, fd2, flags); }
int fcntl(int fd, int cmd, long arg) { return get_fcntl()(fd, cmd, arg); }
int ioctl(int fd, unsigned long request, void* arg) {
  if (auto f = get_ioctl()) return f(fd, request, arg);
  return static_cast<int>(syscall(SYS_ioctl, fd, request, arg));
}
ssize_t read(int fd, void* buf, size_t n) {
  if (auto f = get_read()) return f(fd, buf, n);
  return syscall(SYS_read, fd, buf, n);
}
ssize_t write(int fd, const void* buf, size_t n) {
  if (auto f = get_write()) return f(fd, buf, n);
  return syscall(SYS_write, fd, buf, n);
}
int stat(const char* path, struct stat* st) { return get_stat()(path, st); }
int lstat(const char* path, struct stat* st) { return get_lstat()(path, st); }
int fstat(int fd, struct stat* st) { return get_fstat()(fd, st); }
int fstatat(int dirfd, const char* path, struct stat* st, int flags) { return get_fstatat()(dirfd, path, st, flags); }
int statx(int dirfd, const char* path, int flags, unsigned mask, struct ::statx* buf) {
  if (auto f = get_statx()) return f(dirfd, path, flags, mask, buf);
  return static_cast<int>(syscall(SYS_statx, dirfd, path, flags, mask, buf));
}
int access(const char* path, int mode) { return get_access()(path, mode); }
int faccessat(int dirfd, const char* path, int mode, int flags) { return get_faccessat()(dirfd, path, mode, flags); }
char* realpath(const char* path, char* resolved) { return get_realpath()(path, resolved); }
ssize_t readlink(const char* path, char* buf, size_t n) { return get_readlink()(path, buf, n); }
ssize_t readlinkat(int dirfd, const char* path, char* buf, size_t n) { return get_readlinkat()(dirfd, path, buf, n); }
DIR* opendir(const char* path) { return get_opendir()(path); }
struct dirent* readdir(DIR* d) { return get_readdir()(d); }
int closedir(DIR* d) { return get_closedir()(d); }
int scandir(const char* dir, struct dirent*** list, int (*filter)(const struct dirent*),
            int (*compar)(const struct dirent**, const struct dirent**)) {
  return get_scandir()(dir, list, filter, compar);
}

}  // namespace l6470emu::real
