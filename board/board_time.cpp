// The board's time: the host-time <-> tick mapping and how a host waits for a tick.
#include "board/board_time.hpp"

#include <cmath>

namespace l6470emu {

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
