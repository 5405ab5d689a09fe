// The emulated /sys/class/pwm: pwmchipN for chain N of the board, with npwm, export, unexport
// and, for an exported channel K, pwmK/{period,duty_cycle,enable,polarity} (the kernel's ABI,
// Documentation/ABI/testing/sysfs-class-pwm). The files are memfds: a read shows the value at
// open (as sysfs reads it at the first read), a write(2) or pwrite(2) goes to the board at once
// (DeviceBoard::pwm_write) and fails with the kernel's errno, and so does a write of a stream
// fopen() made. Bytes that reach the memfd past the preload (the C library's own writes: a shell's
// echo into a redirection) go to the board when the last descriptor of the file is closed or
// replaced (dup2), their error returned by close() and said in the log. The board's pwmchips
// (Backend::pwm_chips): in process, or the daemon's (Op::pwm), whose channels outlive a program.
#pragma once

#include <stdio.h>
#include <sys/types.h>

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "linux/preload/sysfs.hpp"

namespace l6470emu::preload {

/// What `path` (absolute, no symlink to follow) is under /sys/class/pwm: Type::none when it is
/// not there (not ours, a chip or channel the board lacks, a channel not exported).
VirtualPath lookup_pwm(std::string_view path);

/// Entries of directory `dir` under /sys/class/pwm (empty for any other).
std::vector<std::pair<std::string, unsigned char>> pwm_dir_entries(std::string_view dir);

/// open() of `path`: true when it is a pwm attribute (`fd` the new descriptor, or -1 with errno
/// set: EACCES for a read of export/unexport or a write of npwm, ENOENT for a channel not exported).
bool open_pwm_file(std::string_view path, int flags, int& fd);

/// Whether any descriptor of a pwm attribute is open (a cheap test before the table's).
bool pwm_fds_exist();
/// write() of `count` bytes at `buf` to `fd`: true when `fd` is a pwm attribute (`result`: the
/// count, or -1 with errno set as the kernel's store would).
bool write_pwm_fd(int fd, const void* buf, std::size_t count, ssize_t& result);
/// `fd` is about to be closed or replaced: the bytes written to its memfd past the preload go to
/// the board now. 0, or the -errno of their write.
long flush_pwm_fd(int fd);
/// `fd` was closed (or replaced): forget it.
void forget_pwm_fd(int fd);
/// fopen() of a pwm attribute that open_pwm_file opened as `fd`: a stream whose writes go to the
/// board (its fflush/fclose fail with the kernel's errno); nullptr when `fd` is not one for writing.
FILE* pwm_stream(int fd, const char* mode);
/// `to` is a copy of `from` (dup): it writes to the same attribute.
void dup_pwm_fd(int from, int to);

}  // namespace l6470emu::preload
