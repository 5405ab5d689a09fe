// A blocking read of a descriptor the board does not own (a pipe, a socket, a terminal) as a
// covered wait of virtual time: the thread counts as waiting until the descriptor is readable, so
// that time can move meanwhile and a read nothing can ever satisfy is seen as a deadlock
// (docs/linux.md, Deadlocks). The read itself stays the C library's.
#pragma once

#include <errno.h>

#include "linux/preload/virtual_time.hpp"

namespace l6470emu::preload {

/// How a wait_until_readable() ended.
enum class ReadWait : unsigned char {
  proceed,      ///< make the real call now (it will not block, or it is not ours to cover)
  interrupted,  ///< a signal handler installed without SA_RESTART ran: the call fails with EINTR
  again,        ///< a signal (or pthread_cancel) ended the wait but the call restarts: act on a
                ///< pending cancellation, then wait again
};

/// Before a read-like call `call` ("read", "recv") of `fd` that would block: waits, as a covered
/// wait, until `fd` is readable (or hung up, or in error). proceed at once when the call would not
/// block: `fd` is readable already, is non-blocking or `nonblocking` says the call is
/// (MSG_DONTWAIT), or is a socket with a receive timeout (SO_RCVTIMEO, real time: the call stays
/// the kernel's). A signal whose handler was installed without SA_RESTART ends it as the kernel's
/// call would (interrupted, errno EINTR); with SA_RESTART everywhere the call restarts (again).
/// The signal that came is not known: any handler without SA_RESTART counts.
ReadWait wait_until_readable(VirtualHostTime& vt, int fd, bool nonblocking, const char* call);

/// After a signal ended a covered wait for a blocking call: whether a handler installed without
/// SA_RESTART exists (the call then fails with EINTR, as the kernel's would; with SA_RESTART
/// everywhere it restarts). The signal that came is not known here: any such handler counts.
bool signal_interrupts_blocking_call();

/// wait_until_readable() as the body of an interposer: inside a Guard, and proceed when the
/// library itself fails (the call then blocks as the kernel's does).
ReadWait covered_read_wait(VirtualHostTime& vt, int fd, const char* call, bool nonblocking = false);

/// The loop every covered read-like interposer runs before its real call: each wait a
/// cancellation point of its own (as_cancellation_point, from the caller's frame). False: the call
/// fails with EINTR (errno set).
template <typename Wait>
[[gnu::always_inline]] inline bool readable_or_interrupted(Wait&& wait_once) {
  for (;;) {
    const ReadWait r = as_cancellation_point(wait_once);
    if (r == ReadWait::proceed) return true;
    if (r == ReadWait::interrupted) {
      errno = EINTR;
      return false;
    }
  }
}

}  // namespace l6470emu::preload
