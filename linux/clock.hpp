// The one place where wall time becomes virtual ticks: a scaled monotonic wall clock, or
// virtual time that moves only when told. Transports (preload, daemon) read it; core/ never does.
#pragma once

#include <cstdint>

#include "core/tick.hpp"
#include "linux/config.hpp"

namespace l6470emu {

/// CLOCK_MONOTONIC in nanoseconds.
std::int64_t monotonic_ns();

/// Maps CLOCK_MONOTONIC to the board's ticks. In wall mode tick = (wall - origin) * scale / 250 ns;
/// in virtual mode the clock holds a tick that only advance() moves (bus traffic advances chains
/// on its own, through run_message).
class BoardClock {
 public:
  explicit BoardClock(const TimeConfig& config);

  bool is_virtual() const { return virtual_; }
  double scale() const { return scale_; }

  /// The tick the board should be at now (wall mode), or the tick advance() reached (virtual mode).
  Tick now() const;
  /// Virtual mode: moves the clock on by `ticks` (wall mode: no effect). Returns the new now().
  Tick advance(Tick ticks);
  /// The CLOCK_MONOTONIC time (ns) at which `tick` is reached in wall mode; in virtual mode, now.
  std::int64_t wall_ns_of(Tick tick) const;

 private:
  bool virtual_;
  double scale_;
  std::int64_t origin_ns_;
  Tick virtual_now_ = 0;
};

}  // namespace l6470emu
