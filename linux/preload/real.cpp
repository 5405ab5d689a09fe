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

// The condition variable functions exist in two versions (GLIBC_2.2.5 for old binaries, and the
// current one): ask for the current one by name, whatever dlsym would pick.
template <typename F>
F resolve_versioned(std::atomic<void*>& slot, const char* name, const char* version) {
  void* p = slot.load(std::memory_order_acquire);
  if (!p) {
    p = dlvsym(RTLD_NEXT, name, version);
    if (!p) p = dlsym(RTLD_NEXT, name);
    slot.store(p, std::memory_order_release);
  }
  return reinterpret_cast<F>(p);
}

#define L6470EMU_REAL_V(ret, name, params, version) \
  using name##_fn = ret(*) params;                  \
  std::atomic<void*> name##_slot{nullptr};          \
  name##_fn get_##name() { return resolve_versioned<name##_fn>(name##_slot, #name, version); }

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
L6470EMU_REAL(ssize_t, readv, (int, const struct iovec*, int))
L6470EMU_REAL(ssize_t, recv, (int, void*, size_t, int))
L6470EMU_REAL(ssize_t, recvfrom, (int, void*, size_t, int, struct sockaddr*, socklen_t*))
L6470EMU_REAL(ssize_t, recvmsg, (int, struct msghdr*, int))
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
L6470EMU_REAL(int, clock_gettime, (clockid_t, struct timespec*))
L6470EMU_REAL(int, gettimeofday, (struct timeval*, void*))
L6470EMU_REAL(time_t, time, (time_t*))
L6470EMU_REAL(int, timespec_get, (struct timespec*, int))
L6470EMU_REAL(int, nanosleep, (const struct timespec*, struct timespec*))
L6470EMU_REAL(int, clock_nanosleep, (clockid_t, int, const struct timespec*, struct timespec*))
L6470EMU_REAL(int, usleep, (useconds_t))
L6470EMU_REAL(int, pause, ())
L6470EMU_REAL(int, sigsuspend, (const sigset_t*))
L6470EMU_REAL(unsigned, sleep, (unsigned))
L6470EMU_REAL(int, select, (int, fd_set*, fd_set*, fd_set*, struct timeval*))
L6470EMU_REAL(int, pselect, (int, fd_set*, fd_set*, fd_set*, const struct timespec*, const sigset_t*))
L6470EMU_REAL(int, poll, (struct pollfd*, nfds_t, int))
L6470EMU_REAL(int, ppoll, (struct pollfd*, nfds_t, const struct timespec*, const sigset_t*))
L6470EMU_REAL(int, epoll_wait, (int, struct epoll_event*, int, int))
L6470EMU_REAL(int, epoll_pwait, (int, struct epoll_event*, int, int, const sigset_t*))
L6470EMU_REAL(int, epoll_pwait2, (int, struct epoll_event*, int, const struct timespec*, const sigset_t*))
L6470EMU_REAL(int, epoll_ctl, (int, int, int, struct epoll_event*))
L6470EMU_REAL_V(int, pthread_cond_wait, (pthread_cond_t*, pthread_mutex_t*), "GLIBC_2.3.2")
L6470EMU_REAL_V(int, pthread_cond_timedwait, (pthread_cond_t*, pthread_mutex_t*, const struct timespec*), "GLIBC_2.3.2")
L6470EMU_REAL(int, pthread_cond_clockwait, (pthread_cond_t*, pthread_mutex_t*, clockid_t, const struct timespec*))
L6470EMU_REAL_V(int, pthread_cond_signal, (pthread_cond_t*), "GLIBC_2.3.2")
L6470EMU_REAL_V(int, pthread_cond_broadcast, (pthread_cond_t*), "GLIBC_2.3.2")
L6470EMU_REAL(int, sem_wait, (sem_t*))
L6470EMU_REAL(int, sem_timedwait, (sem_t*, const struct timespec*))
L6470EMU_REAL(int, sem_clockwait, (sem_t*, clockid_t, const struct timespec*))
L6470EMU_REAL(int, sem_trywait, (sem_t*))
L6470EMU_REAL(int, sem_post, (sem_t*))
L6470EMU_REAL(int, pthread_create, (pthread_t*, const pthread_attr_t*, void* (*)(void*), void*))
L6470EMU_REAL(int, pthread_join, (pthread_t, void**))
L6470EMU_REAL(pid_t, waitpid, (pid_t, int*, int))
L6470EMU_REAL(pid_t, wait4, (pid_t, int*, int, struct rusage*))
L6470EMU_REAL(int, waitid, (idtype_t, id_t, siginfo_t*, int))
L6470EMU_REAL(int, pthread_mutex_lock, (pthread_mutex_t*))
L6470EMU_REAL(int, pthread_mutex_trylock, (pthread_mutex_t*))
L6470EMU_REAL(int, pthread_mutex_unlock, (pthread_mutex_t*))
L6470EMU_REAL(int, pthread_cancel, (pthread_t))
L6470EMU_REAL(int, timerfd_create, (int, int))
L6470EMU_REAL(int, timerfd_settime, (int, int, const struct itimerspec*, struct itimerspec*))
L6470EMU_REAL(int, timerfd_gettime, (int, struct itimerspec*))

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
ssize_t readv(int fd, const struct iovec* iov, int n) { return get_readv()(fd, iov, n); }
ssize_t recv(int fd, void* buf, size_t n, int flags) { return get_recv()(fd, buf, n, flags); }
ssize_t recvfrom(int fd, void* buf, size_t n, int flags, struct sockaddr* from, socklen_t* from_len) {
  return get_recvfrom()(fd, buf, n, flags, from, from_len);
}
ssize_t recvmsg(int fd, struct msghdr* msg, int flags) { return get_recvmsg()(fd, msg, flags); }
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


// Time and waits. A function the C library lacks (an older glibc) fails with ENOSYS.
namespace {
int missing() {
  errno = ENOSYS;
  return -1;
}
}  // namespace

int clock_gettime(clockid_t clock, struct timespec* ts) {
  if (auto f = get_clock_gettime()) return f(clock, ts);
  return static_cast<int>(syscall(SYS_clock_gettime, clock, ts));
}
int gettimeofday(struct timeval* tv, void* tz) { return get_gettimeofday()(tv, tz); }
time_t time(time_t* t) { return get_time()(t); }
int timespec_get(struct timespec* ts, int base) { return get_timespec_get()(ts, base); }
int nanosleep(const struct timespec* req, struct timespec* rem) { return get_nanosleep()(req, rem); }
int clock_nanosleep(clockid_t clock, int flags, const struct timespec* req, struct timespec* rem) {
  return get_clock_nanosleep()(clock, flags, req, rem);
}
int usleep(useconds_t us) { return get_usleep()(us); }
int pause() { return get_pause()(); }
int sigsuspend(const sigset_t* mask) { return get_sigsuspend()(mask); }
unsigned sleep(unsigned seconds) { return get_sleep()(seconds); }
int select(int n, fd_set* r, fd_set* w, fd_set* e, struct timeval* timeout) { return get_select()(n, r, w, e, timeout); }
int pselect(int n, fd_set* r, fd_set* w, fd_set* e, const struct timespec* timeout, const sigset_t* mask) {
  return get_pselect()(n, r, w, e, timeout, mask);
}
int poll(struct pollfd* fds, nfds_t n, int timeout_ms) {
  if (auto f = get_poll()) return f(fds, n, timeout_ms);
  return static_cast<int>(syscall(SYS_poll, fds, n, timeout_ms));
}
int ppoll(struct pollfd* fds, nfds_t n, const struct timespec* timeout, const sigset_t* mask) {
  return get_ppoll()(fds, n, timeout, mask);
}
int epoll_wait(int epfd, struct epoll_event* events, int max, int timeout_ms) {
  return get_epoll_wait()(epfd, events, max, timeout_ms);
}
int epoll_pwait(int epfd, struct epoll_event* events, int max, int timeout_ms, const sigset_t* mask) {
  return get_epoll_pwait()(epfd, events, max, timeout_ms, mask);
}
int epoll_pwait2(int epfd, struct epoll_event* events, int max, const struct timespec* timeout, const sigset_t* mask) {
  if (auto f = get_epoll_pwait2()) return f(epfd, events, max, timeout, mask);
  return missing();
}
int epoll_ctl(int epfd, int op, int fd, struct epoll_event* event) { return get_epoll_ctl()(epfd, op, fd, event); }
int pthread_cond_wait(pthread_cond_t* c, pthread_mutex_t* m) { return get_pthread_cond_wait()(c, m); }
int pthread_cond_timedwait(pthread_cond_t* c, pthread_mutex_t* m, const struct timespec* abstime) {
  return get_pthread_cond_timedwait()(c, m, abstime);
}
int pthread_cond_clockwait(pthread_cond_t* c, pthread_mutex_t* m, clockid_t clock, const struct timespec* abstime) {
  if (auto f = get_pthread_cond_clockwait()) return f(c, m, clock, abstime);
  return ENOSYS;
}
int pthread_cond_signal(pthread_cond_t* c) { return get_pthread_cond_signal()(c); }
int pthread_cond_broadcast(pthread_cond_t* c) { return get_pthread_cond_broadcast()(c); }
int sem_wait(sem_t* s) { return get_sem_wait()(s); }
int sem_timedwait(sem_t* s, const struct timespec* abstime) { return get_sem_timedwait()(s, abstime); }
int sem_clockwait(sem_t* s, clockid_t clock, const struct timespec* abstime) {
  if (auto f = get_sem_clockwait()) return f(s, clock, abstime);
  return missing();
}
int sem_trywait(sem_t* s) { return get_sem_trywait()(s); }
int sem_post(sem_t* s) { return get_sem_post()(s); }
int pthread_create(pthread_t* t, const pthread_attr_t* attr, void* (*fn)(void*), void* arg) {
  return get_pthread_create()(t, attr, fn, arg);
}
int pthread_join(pthread_t t, void** result) { return get_pthread_join()(t, result); }
pid_t waitpid(pid_t pid, int* status, int options) { return get_waitpid()(pid, status, options); }
pid_t wait4(pid_t pid, int* status, int options, struct rusage* usage) { return get_wait4()(pid, status, options, usage); }
int waitid(idtype_t idtype, id_t id, siginfo_t* info, int options) { return get_waitid()(idtype, id, info, options); }
int pthread_mutex_lock(pthread_mutex_t* m) { return get_pthread_mutex_lock()(m); }
int pthread_mutex_trylock(pthread_mutex_t* m) { return get_pthread_mutex_trylock()(m); }
int pthread_mutex_unlock(pthread_mutex_t* m) { return get_pthread_mutex_unlock()(m); }
int pthread_cancel(pthread_t t) { return get_pthread_cancel()(t); }
int timerfd_create(int clock, int flags) { return get_timerfd_create()(clock, flags); }
int timerfd_settime(int fd, int flags, const struct itimerspec* value, struct itimerspec* old) {
  return get_timerfd_settime()(fd, flags, value, old);
}
int timerfd_gettime(int fd, struct itimerspec* value) { return get_timerfd_gettime()(fd, value); }

}  // namespace l6470emu::real
