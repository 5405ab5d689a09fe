// The board's time: the host's real clocks and the host-time <-> tick mapping.
#include "linux/clock.hpp"

#include <dlfcn.h>
#include <time.h>

#include <cmath>

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

BoardTime::BoardTime(const TimeConfig& config, HostClock& host)
    : host_(host),
      virtual_(config.virtual_time),
      scale_(config.virtual_time ? 1.0 : (config.scale > 0 ? config.scale : 1.0)),
      origin_ns_(config.virtual_time ? kVirtualMonotonicOrigin : host.monotonic_ns()),
      realtime_offset_ns_(host.realtime_ns() - origin_ns_) {}

Tick BoardTime::now() const {
  if (virtual_) return virtual_now_.load(std::memory_order_acquire);
  return tick_of(host_.monotonic_ns());
}

Tick BoardTime::tick_of(std::int64_t host_ns) const {
  const std::int64_t dt = host_ns - origin_ns_;
  if (dt <= 0) return 0;
  if (scale_ == 1.0) return static_cast<Tick>(dt / 250);
  return static_cast<Tick>(static_cast<long double>(dt) * scale_ / 250.0L);
}

std::int64_t BoardTime::host_ns_of(Tick tick) const {
  if (scale_ == 1.0) return origin_ns_ + static_cast<std::int64_t>(tick) * 250;
  // Rounded up, so that tick_of(host_ns_of(t)) == t: the host never sees the tick early.
  return origin_ns_ + static_cast<std::int64_t>(std::ceil(static_cast<long double>(tick) * 250.0L / scale_));
}

std::int64_t BoardTime::realtime_offset_ns() const {
  // Virtual mode: REALTIME started at the real time of the start and moves with virtual time.
  if (virtual_) return realtime_offset_ns_;
  return host_.realtime_ns() - host_.monotonic_ns();
}

void BoardTime::wait_until(Tick tick) {
  if (!virtual_) {
    host_.sleep_until(host_ns_of(tick));
    return;
  }
  if (Waiter* w = waiter()) {
    w->wait_until(tick);
    return;
  }
  set_now(tick);
}

Tick BoardTime::set_now(Tick tick) {
  Tick cur = virtual_now_.load(std::memory_order_acquire);
  while (cur < tick && !virtual_now_.compare_exchange_weak(cur, tick, std::memory_order_acq_rel)) {
  }
  return cur < tick ? tick : cur;
}

}  // namespace l6470emu
