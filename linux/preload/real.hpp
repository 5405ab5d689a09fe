// The C library's own functions behind the ones the preload library replaces, found with
// dlsym(RTLD_NEXT) on first use (other libraries' constructors may call them before ours).
#pragma once

#include <dirent.h>
#include <poll.h>
#include <pthread.h>
#include <semaphore.h>
#include <signal.h>
#include <stdio.h>
#include <sys/epoll.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <sys/wait.h>
#include <sys/resource.h>
#include <time.h>

struct statx;
struct itimerspec;

namespace l6470emu::real {

int open(const char* path, int flags, mode_t mode);
int openat(int dirfd, const char* path, int flags, mode_t mode);
FILE* fopen(const char* path, const char* mode);
int close(int fd);
int dup(int fd);
int dup2(int fd, int fd2);
int dup3(int fd, int fd2, int flags);
int fcntl(int fd, int cmd, long arg);
int ioctl(int fd, unsigned long request, void* arg);
ssize_t read(int fd, void* buf, size_t n);
ssize_t readv(int fd, const struct iovec* iov, int n);
ssize_t recv(int fd, void* buf, size_t n, int flags);
ssize_t recvfrom(int fd, void* buf, size_t n, int flags, struct sockaddr* from, socklen_t* from_len);
ssize_t recvmsg(int fd, struct msghdr* msg, int flags);
ssize_t write(int fd, const void* buf, size_t n);
int stat(const char* path, struct stat* st);
int lstat(const char* path, struct stat* st);
int fstat(int fd, struct stat* st);
int fstatat(int dirfd, const char* path, struct stat* st, int flags);
int statx(int dirfd, const char* path, int flags, unsigned mask, struct ::statx* buf);
int access(const char* path, int mode);
int faccessat(int dirfd, const char* path, int mode, int flags);
char* realpath(const char* path, char* resolved);
ssize_t readlink(const char* path, char* buf, size_t n);
ssize_t readlinkat(int dirfd, const char* path, char* buf, size_t n);
DIR* opendir(const char* path);
struct dirent* readdir(DIR* d);
int closedir(DIR* d);
int scandir(const char* dir, struct dirent*** list, int (*filter)(const struct dirent*),
            int (*compar)(const struct dirent**, const struct dirent**));

// Time and waits (virtual host time).
int clock_gettime(clockid_t clock, struct timespec* ts);
int gettimeofday(struct timeval* tv, void* tz);
time_t time(time_t* t);
int timespec_get(struct timespec* ts, int base);
int nanosleep(const struct timespec* req, struct timespec* rem);
int clock_nanosleep(clockid_t clock, int flags, const struct timespec* req, struct timespec* rem);
int usleep(useconds_t us);
int pause();
int sigsuspend(const sigset_t* mask);
unsigned sleep(unsigned seconds);
int select(int n, fd_set* r, fd_set* w, fd_set* e, struct timeval* timeout);
int pselect(int n, fd_set* r, fd_set* w, fd_set* e, const struct timespec* timeout, const sigset_t* mask);
int poll(struct pollfd* fds, nfds_t n, int timeout_ms);
int ppoll(struct pollfd* fds, nfds_t n, const struct timespec* timeout, const sigset_t* mask);
int epoll_wait(int epfd, struct epoll_event* events, int max, int timeout_ms);
int epoll_pwait(int epfd, struct epoll_event* events, int max, int timeout_ms, const sigset_t* mask);
int epoll_pwait2(int epfd, struct epoll_event* events, int max, const struct timespec* timeout, const sigset_t* mask);
int epoll_ctl(int epfd, int op, int fd, struct epoll_event* event);
int pthread_cond_wait(pthread_cond_t* c, pthread_mutex_t* m);
int pthread_cond_timedwait(pthread_cond_t* c, pthread_mutex_t* m, const struct timespec* abstime);
int pthread_cond_clockwait(pthread_cond_t* c, pthread_mutex_t* m, clockid_t clock, const struct timespec* abstime);
int pthread_cond_signal(pthread_cond_t* c);
int pthread_cond_broadcast(pthread_cond_t* c);
int sem_wait(sem_t* s);
int sem_timedwait(sem_t* s, const struct timespec* abstime);
int sem_clockwait(sem_t* s, clockid_t clock, const struct timespec* abstime);
int sem_trywait(sem_t* s);
int sem_post(sem_t* s);
int pthread_create(pthread_t* t, const pthread_attr_t* attr, void* (*fn)(void*), void* arg);
int pthread_join(pthread_t t, void** result);
pid_t waitpid(pid_t pid, int* status, int options);
pid_t wait4(pid_t pid, int* status, int options, struct rusage* usage);
int waitid(idtype_t idtype, id_t id, siginfo_t* info, int options);
int pthread_mutex_lock(pthread_mutex_t* m);
int pthread_mutex_trylock(pthread_mutex_t* m);
int pthread_mutex_unlock(pthread_mutex_t* m);
int pthread_cancel(pthread_t t);
int timerfd_create(int clock, int flags);
int timerfd_settime(int fd, int flags, const struct itimerspec* value, struct itimerspec* old);
int timerfd_gettime(int fd, struct itimerspec* value);

}  // namespace l6470emu::real
