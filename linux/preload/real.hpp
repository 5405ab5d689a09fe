// The C library's own functions behind the ones the preload library replaces, found with
// dlsym(RTLD_NEXT) on first use (other libraries' constructors may call them before ours).
#pragma once

#include <dirent.h>
#include <stdio.h>
#include <sys/stat.h>
#include <sys/types.h>

struct statx;

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

}  // namespace l6470emu::real
