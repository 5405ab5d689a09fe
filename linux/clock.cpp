// Wall clock to ticks.
#include "linux/clock.hpp"

#include <time.h>

#include <cmath>

namespace l6470emu {

std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

BoardClock::BoardClock(const TimeConfig& config)
    : virtual_(config.virtual_time), scale_(config.scale > 0 ? config.scale : 1.0), origin_ns_(monotonic_ns()) {}

Tick BoardClock::now() const {
  if (virtual_) return virtual_now_;
  const std::int64_t dt = monotonic_ns() - origin_ns_;
  if (dt <= 0) return 0;
  if (scale_ == 1.0) return static_cast<Tick>(dt / 250);
  return static_cast<Tick>(static_cast<long double>(dt) * scale_ / 250.0L);
}

Tick BoardClock::advance(Tick ticks) {
  if (virtual_) virtual_now_ += ticks;
  return now();
}

std::int64_t BoardClock::wall_ns_of(Tick tick) const {
  if (virtual_) return monotonic_ns();
  if (scale_ == 1.0) return origin_ns_ + static_cast<std::int64_t>(tick) * 250;
  return origin_ns_ + static_cast<std::int64_t>(std::ceil(static_cast<long double>(tick) * 250.0L / scale_));
}

}  // namespace l6470emu
