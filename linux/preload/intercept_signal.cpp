// pause() and sigsuspend() as covered waits (virtual time): the thread waits for nothing but a
// signal, so when every thread waits and no timer can send one, the run is a deadlock, reported
// with the call's name (docs/linux.md, Deadlocks), instead of hanging where time cannot see it.
// A signal ends the wait as the kernel's call would: its handler runs, and the call fails with EINTR.
#include <errno.h>
#include <signal.h>
#include <unistd.h>

#include "linux/preload/real.hpp"
#include "linux/preload/virtual_time.hpp"

namespace l6470emu::preload {
namespace {

// A wait for a signal only, with `mask` blocked meanwhile (nullptr: the thread's own mask).
int wait_for_a_signal(VirtualHostTime& vt, const sigset_t* mask, const char* call) {
  VirtualScheduler::Wait w;
  w.call = call;
  w.sigmask = mask;
  while (vt.wait(w) != VirtualScheduler::End::interrupted) {
  }
  errno = EINTR;
  return -1;
}

}  // namespace
}  // namespace l6470emu::preload

using namespace l6470emu;
using namespace l6470emu::preload;

extern "C" {

__attribute__((visibility("default"))) int pause(void) {
  VirtualHostTime* vt = virtual_time();
  if (!vt) return real::pause();
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return wait_for_a_signal(*vt, nullptr, "pause");
    } catch (...) {
      return real::pause();
    }
  });
}

__attribute__((visibility("default"))) int sigsuspend(const sigset_t* mask) {
  VirtualHostTime* vt = virtual_time();
  if (!vt || is_null(mask)) return real::sigsuspend(mask);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return wait_for_a_signal(*vt, mask, "sigsuspend");
    } catch (...) {
      return real::sigsuspend(mask);
    }
  });
}

}  // extern "C"
