// readv, recv, recvfrom and recvmsg (and their _chk variants) in virtual time: a call that would
// block first waits for data as a covered wait (descriptor_wait.hpp), so that a thread reading its
// own pipe or socket counts as waiting and a read nothing can satisfy is a deadlock. read() is
// intercept_io.cpp's. Emulated descriptors, wall mode and the library's own calls: the C library's.
#include <sys/socket.h>
#include <sys/uio.h>

#include "linux/preload/descriptor_wait.hpp"
#include "linux/preload/real.hpp"

using namespace l6470emu;
using namespace l6470emu::preload;

namespace {

// The virtual time a read-like call of `fd` waits in, or nullptr (wall mode, inside the library,
// an emulated descriptor, whose reads are the board's).
VirtualHostTime* covering(int fd) {
  VirtualHostTime* vt = virtual_time();
  return vt && !fd_entry(fd) ? vt : nullptr;
}

}  // namespace

extern "C" {

void __chk_fail(void) __attribute__((noreturn));

__attribute__((visibility("default"))) ssize_t readv(int fd, const struct iovec* iov, int n) {
  if (VirtualHostTime* vt = covering(fd))
    if (!readable_or_interrupted([&] { return covered_read_wait(*vt, fd, "readv"); })) return -1;
  return real::readv(fd, iov, n);
}

__attribute__((visibility("default"))) ssize_t recv(int fd, void* buf, size_t n, int flags) {
  if (VirtualHostTime* vt = covering(fd))
    if (!readable_or_interrupted([&] { return covered_read_wait(*vt, fd, "recv", flags & MSG_DONTWAIT); })) return -1;
  return real::recv(fd, buf, n, flags);
}

__attribute__((visibility("default"))) ssize_t __recv_chk(int fd, void* buf, size_t n, size_t buflen, int flags) {
  if (n > buflen) __chk_fail();
  return recv(fd, buf, n, flags);
}

__attribute__((visibility("default"))) ssize_t recvfrom(int fd, void* buf, size_t n, int flags, struct sockaddr* from,
                                                        socklen_t* from_len) {
  if (VirtualHostTime* vt = covering(fd))
    if (!readable_or_interrupted([&] { return covered_read_wait(*vt, fd, "recvfrom", flags & MSG_DONTWAIT); }))
      return -1;
  return real::recvfrom(fd, buf, n, flags, from, from_len);
}

__attribute__((visibility("default"))) ssize_t __recvfrom_chk(int fd, void* buf, size_t n, size_t buflen, int flags,
                                                              struct sockaddr* from, socklen_t* from_len) {
  if (n > buflen) __chk_fail();
  return recvfrom(fd, buf, n, flags, from, from_len);
}

__attribute__((visibility("default"))) ssize_t recvmsg(int fd, struct msghdr* msg, int flags) {
  if (VirtualHostTime* vt = covering(fd))
    if (!readable_or_interrupted([&] { return covered_read_wait(*vt, fd, "recvmsg", flags & MSG_DONTWAIT); }))
      return -1;
  return real::recvmsg(fd, msg, flags);
}

}  // extern "C"
