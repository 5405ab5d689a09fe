// The virtual clock of the model: one tick is the chip's own 250 ns tick.
// Nothing here reads a wall clock; transports convert wall time to ticks.
#pragma once

#include <cstdint>
#include <limits>

namespace l6470emu {

/// A point in virtual time, counted in 250 ns ticks since the chain was created.
using Tick = std::uint64_t;

/// Ticks per second of virtual time (1 s / 250 ns).
inline constexpr Tick kTicksPerSecond = 4'000'000;

/// Ticks per microsecond of virtual time.
inline constexpr Tick kTicksPerMicrosecond = 4;

/// "No event scheduled": returned by next_event_tick() when nothing will happen on its own.
inline constexpr Tick kNever = std::numeric_limits<Tick>::max();

/// Whole ticks in `us` microseconds.
constexpr Tick ticks_from_us(std::uint64_t us) { return us * kTicksPerMicrosecond; }

/// Whole ticks in `ms` milliseconds.
constexpr Tick ticks_from_ms(std::uint64_t ms) { return ms * 1000 * kTicksPerMicrosecond; }

}  // namespace l6470emu
