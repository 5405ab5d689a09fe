// A periodic pulse train on an input pin (a timer's PWM output on STCK): when its edges fall,
// worked out in closed form so that a train costs nothing per pulse. Not a timer: no counter,
// no interrupts (the firmware front's timers make trains).
#pragma once

#include <cstdint>

#include "core/tick.hpp"

namespace l6470emu {

/// Pulses of a clock counting at `clock_hz`: pulse k (from 0) rises `(first + k) × period_counts`
/// counts after `start` and falls `high_counts` later. A count of `c` counts after `start` is the board
/// tick start + floor(c × kTicksPerSecond / clock_hz), so a period need not be whole ticks and
/// the train never drifts (1 kHz from an 84 MHz timer is exactly 4000 ticks a pulse).
struct PulseTrain {
  Tick start = 0;                    ///< the first rising edge, board ticks
  std::uint64_t clock_hz = 4'000'000;  ///< the counter's clock (the board's tick rate by default)
  std::uint64_t period_counts = 2;   ///< counts from one rising edge to the next (>= 1)
  std::uint64_t high_counts = 1;     ///< counts the pin stays high (0 < high < period)
  std::uint64_t count = 0;           ///< pulses in all; 0 = until stopped
  std::uint64_t first = 0;           ///< periods from `start` before the first pulse made (a timer's output enabled mid-run)

  /// Whether the description makes pulses (a clock, a period, a high time shorter than it).
  bool valid() const { return clock_hz > 0 && period_counts > 0 && high_counts > 0 && high_counts < period_counts; }
  /// The board tick `counts` counts after start.
  Tick tick_at(std::uint64_t counts) const;
  /// The tick pulse `k` rises at.
  Tick rise_tick(std::uint64_t k) const { return tick_at((first + k) * period_counts); }
  /// The tick pulse `k` falls at.
  Tick fall_tick(std::uint64_t k) const { return tick_at((first + k) * period_counts + high_counts); }
  /// How many pulses have risen at or before `tick` (capped at count).
  std::uint64_t rises_through(Tick tick) const { return edges_through(tick, 0); }
  /// How many pulses have fallen at or before `tick` (capped at count).
  std::uint64_t falls_through(Tick tick) const { return edges_through(tick, high_counts); }

 private:
  std::uint64_t edges_through(Tick tick, std::uint64_t offset_counts) const;
};

}  // namespace l6470emu
