// The host's real clocks (the kernel's, through the C library) for the board's time.
#include "linux/clock.hpp"

#include <dlfcn.h>
#include <time.h>

namespace l6470emu {
namespace {

using ClockGettime = int (*)(clockid_t, timespec*);
using ClockNanosleep = int (*)(clockid_t, int, const timespec*, timespec*);

// The C library's functions, not a replacement the preload library (or another) put in front:
// RTLD_NEXT from here finds the next definition after the object this code lives in.
template <typename F>
F libc_function(const char* name, F fallback) {
  void* p = dlsym(RTLD_NEXT, name);
  return p ? reinterpret_cast<F>(p) : fallback;
}

ClockGettime real_clock_gettime() {
  static const ClockGettime f = libc_function<ClockGettime>("clock_gettime", &::clock_gettime);
  return f;
}

ClockNanosleep real_clock_nanosleep() {
  static const ClockNanosleep f = libc_function<ClockNanosleep>("clock_nanosleep", &::clock_nanosleep);
  return f;
}

std::int64_t read_clock(clockid_t id) {
  timespec ts{};
  real_clock_gettime()(id, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

// How long before a deadline sleeping stops and spinning starts: a timed sleep here overshoots
// by 50-270 µs (notes/host-time.md §3), so the last stretch is spun on the clock.
constexpr std::int64_t kSpinNs = 300'000;

class RealHostClock final : public HostClock {
 public:
  std::int64_t monotonic_ns() override { return read_clock(CLOCK_MONOTONIC); }
  // No time-stamp counter read: the tick the kernel last kept (1-4 ms old), from the vDSO.
  std::int64_t coarse_monotonic_ns() override { return read_clock(CLOCK_MONOTONIC_COARSE); }
  std::int64_t realtime_ns() override { return read_clock(CLOCK_REALTIME); }
  void sleep_until(std::int64_t deadline) override {
    std::int64_t now = monotonic_ns();
    if (deadline - now > kSpinNs) {
      const std::int64_t wake = deadline - kSpinNs;
      const timespec ts{static_cast<time_t>(wake / 1'000'000'000), static_cast<long>(wake % 1'000'000'000)};
      while (real_clock_nanosleep()(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
      }
      now = monotonic_ns();
    }
    while (now < deadline) now = monotonic_ns();
  }
};

}  // namespace

HostClock& real_host_clock() {
  static RealHostClock clock;
  return clock;
}

std::int64_t monotonic_ns() { return read_clock(CLOCK_MONOTONIC); }

}  // namespace l6470emu
