// The emulated /sys/class/pwm: pwmchipN for chain N of the board, with npwm, export, unexport
// and, for an exported channel K, pwmK/{period,duty_cycle,enable,polarity} (the kernel's ABI,
// Documentation/ABI/testing/sysfs-class-pwm). The files are memfds: a read shows the value at
// open (as sysfs reads it at the first read), a write(2) or pwrite(2) goes to the board at once
// (DeviceBoard::pwm_write) and fails with the kernel's errno. Only with a backend that offers
// pwmchips (Backend::pwm_chips: the board in process; not yet the daemon).
#pragma once

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
/// `fd` was closed (or replaced): forget it.
void forget_pwm_fd(int fd);
/// `to` is a copy of `from` (dup): it writes to the same attribute.
void dup_pwm_fd(int from, int to);

}  // namespace l6470emu::preload
