// Blocking reads of descriptors the board does not own as covered waits (descriptor_wait.hpp).
#include "linux/preload/descriptor_wait.hpp"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>

#include "linux/preload/real.hpp"

namespace l6470emu::preload {
namespace {

// Whether `fd` is a socket with a receive timeout (the call then ends in real time by itself).
bool socket_with_receive_timeout(int fd) {
  struct stat st {};
  if (real::fstat(fd, &st) != 0 || !S_ISSOCK(st.st_mode)) return false;
  timeval tv{};
  socklen_t len = sizeof tv;
  return getsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, &len) == 0 && (tv.tv_sec != 0 || tv.tv_usec != 0);
}

}  // namespace

bool signal_interrupts_blocking_call() {
  for (int sig = 1; sig < NSIG; ++sig) {
    struct sigaction sa {};
    if (sigaction(sig, nullptr, &sa) != 0) continue;
    const bool handled = (sa.sa_flags & SA_SIGINFO) ? sa.sa_sigaction != nullptr
                                                    : sa.sa_handler != SIG_DFL && sa.sa_handler != SIG_IGN;
    if (handled && !(sa.sa_flags & SA_RESTART)) return true;
  }
  return false;
}

ReadWait wait_until_readable(VirtualHostTime& vt, int fd, bool nonblocking, const char* call) {
  pollfd p{fd, POLLIN, 0};
  if (nonblocking || real::poll(&p, 1, 0) != 0) return ReadWait::proceed;  // readable, hung up, EBADF...
  const int flags = real::fcntl(fd, F_GETFL, 0);
  if (flags < 0 || (flags & O_NONBLOCK) || socket_with_receive_timeout(fd)) return ReadWait::proceed;
  VirtualScheduler::Wait w;
  w.call = call;
  w.fds = std::span<const pollfd>(&p, 1);
  if (vt.wait(w) != VirtualScheduler::End::interrupted) return ReadWait::proceed;
  // Data that came with the signal is read, as the kernel's call would have returned it.
  if (real::poll(&p, 1, 0) != 0) return ReadWait::proceed;
  return signal_interrupts_blocking_call() ? ReadWait::interrupted : ReadWait::again;
}

ReadWait covered_read_wait(VirtualHostTime& vt, int fd, const char* call, bool nonblocking) {
  Guard guard;
  try {
    return wait_until_readable(vt, fd, nonblocking, call);
  } catch (...) {
    return ReadWait::proceed;
  }
}

}  // namespace l6470emu::preload
