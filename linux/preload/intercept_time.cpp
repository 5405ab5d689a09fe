// Clock reads and sleeps on virtual time (clock_gettime, gettimeofday, time, timespec_get, nanosleep,
// clock_nanosleep, usleep, sleep), one wrapper per public symbol: glibc calls itself through
// internal aliases. CPU-time clocks, and every call in wall mode, go to the C library.
#include <errno.h>
#include <sys/time.h>
#include <time.h>
#include <unistd.h>

#include "linux/preload/real.hpp"
#include "linux/preload/virtual_time.hpp"

using namespace l6470emu;
using namespace l6470emu::preload;

namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;

timespec to_timespec(std::int64_t ns) {
  if (ns < 0) ns = 0;
  return {static_cast<time_t>(ns / kNsPerSecond), static_cast<long>(ns % kNsPerSecond)};
}

// clock_nanosleep on a virtual clock: 0 or an error number (EINTR with `rem` for relative sleeps).
// The kernel's rules: a timespec with tv_sec < 0 or tv_nsec outside [0, 10^9) is EINVAL, relative
// or absolute; a time is saturated at KTIME_MAX, and a sleep until then never ends.
int virtual_sleep(VirtualHostTime& vt, clockid_t clock, int flags, const timespec* req, timespec* rem,
                  const char* call) {
  if (!kernel_valid(*req)) return EINVAL;
  const bool absolute = flags & TIMER_ABSTIME;
  const std::int64_t start = vt.now_ns(clock);
  const std::int64_t ns = saturated_ns(*req);
  const std::int64_t deadline_ns = absolute ? ns : add_saturated(start, ns);
  VirtualScheduler::Wait w;
  w.call = call;
  w.deadline = absolute ? vt.tick_at(clock, deadline_ns) : vt.tick_after(ns);
  w.timeout_beyond_end = w.deadline == kNever;
  if (w.deadline <= vt.tick_after(0)) {  // a zero sleep (a yield, sleep(0) in a loop): a look at time
    vt.look();
    return 0;
  }
  if (vt.wait(w) != VirtualScheduler::End::interrupted) return 0;
  if (!absolute && rem) *rem = to_timespec(deadline_ns - vt.now_ns(clock));
  return EINTR;
}

}  // namespace

extern "C" {

__attribute__((visibility("default"))) int clock_gettime(clockid_t clock, struct timespec* ts) noexcept {
  VirtualHostTime* vt = virtual_time();
  if (!vt || !VirtualHostTime::is_virtual_clock(clock) || is_null(ts)) return real::clock_gettime(clock, ts);
  Guard guard;
  try {
    vt->look();
    *ts = to_timespec(vt->now_ns(clock));
    return 0;
  } catch (...) {
    return real::clock_gettime(clock, ts);
  }
}

__attribute__((visibility("default"))) int gettimeofday(struct timeval* tv, void* tz) noexcept {
  VirtualHostTime* vt = virtual_time();
  if (!vt || is_null(tv)) return real::gettimeofday(tv, tz);
  Guard guard;
  try {
    if (tz) real::gettimeofday(nullptr, tz);
    vt->look();
    const std::int64_t ns = vt->now_ns(CLOCK_REALTIME);
    tv->tv_sec = static_cast<time_t>(ns / kNsPerSecond);
    tv->tv_usec = static_cast<suseconds_t>(ns % kNsPerSecond / 1000);
    return 0;
  } catch (...) {
    return real::gettimeofday(tv, tz);
  }
}

__attribute__((visibility("default"))) time_t time(time_t* t) noexcept {
  VirtualHostTime* vt = virtual_time();
  if (!vt) return real::time(t);
  Guard guard;
  try {
    vt->look();
    const time_t s = static_cast<time_t>(vt->now_ns(CLOCK_REALTIME) / kNsPerSecond);
    if (t) *t = s;
    return s;
  } catch (...) {
    return real::time(t);
  }
}

__attribute__((visibility("default"))) int timespec_get(struct timespec* ts, int base) noexcept {
  VirtualHostTime* vt = virtual_time();
  if (!vt || base != TIME_UTC || is_null(ts)) return real::timespec_get(ts, base);
  Guard guard;
  try {
    vt->look();
    *ts = to_timespec(vt->now_ns(CLOCK_REALTIME));
    return base;
  } catch (...) {
    return real::timespec_get(ts, base);
  }
}

__attribute__((visibility("default"))) int clock_nanosleep(clockid_t clock, int flags, const struct timespec* req,
                                                           struct timespec* rem) {
  VirtualHostTime* vt = virtual_time();
  if (!vt || is_null(req) || (clock != CLOCK_MONOTONIC && clock != CLOCK_REALTIME && clock != CLOCK_BOOTTIME &&
                      clock != CLOCK_TAI))
    return real::clock_nanosleep(clock, flags, req, rem);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return virtual_sleep(*vt, clock, flags, req, rem, "clock_nanosleep");
    } catch (...) {
      return real::clock_nanosleep(clock, flags, req, rem);
    }
  });
}

__attribute__((visibility("default"))) int nanosleep(const struct timespec* req, struct timespec* rem) {
  VirtualHostTime* vt = virtual_time();
  if (!vt || is_null(req)) return real::nanosleep(req, rem);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      const int r = virtual_sleep(*vt, CLOCK_MONOTONIC, 0, req, rem, "nanosleep");
      if (r == 0) return 0;
      errno = r;
      return -1;
    } catch (...) {
      return real::nanosleep(req, rem);
    }
  });
}

__attribute__((visibility("default"))) int usleep(useconds_t us) {
  VirtualHostTime* vt = virtual_time();
  if (!vt) return real::usleep(us);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      const timespec req = to_timespec(std::int64_t{us} * 1000);
      const int r = virtual_sleep(*vt, CLOCK_MONOTONIC, 0, &req, nullptr, "usleep");
      if (r == 0) return 0;
      errno = r;
      return -1;
    } catch (...) {
      return real::usleep(us);
    }
  });
}

__attribute__((visibility("default"))) unsigned sleep(unsigned seconds) {
  VirtualHostTime* vt = virtual_time();
  if (!vt) return real::sleep(seconds);
  return as_cancellation_point([&]() __attribute__((noinline)) -> unsigned {
    Guard guard;
    try {
      const timespec req{static_cast<time_t>(seconds), 0};
      timespec rem{};
      const int saved = errno;
      if (virtual_sleep(*vt, CLOCK_MONOTONIC, 0, &req, &rem, "sleep") == 0) {
        errno = saved;
        return 0;
      }
      return static_cast<unsigned>(rem.tv_sec) + (rem.tv_nsec >= 500'000'000 ? 1 : 0);  // as glibc rounds
    } catch (...) {
      return real::sleep(seconds);
    }
  });
}

}  // extern "C"
