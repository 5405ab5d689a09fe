// The event-driven motion engine: the same rules as reference_tick()
// (docs/motion-rules.md), but runs of uniform ticks are jumped in closed form
// with exact integer arithmetic, so the cost does not grow with simulated time.
#pragma once

#include <cstdint>

#include "core/motion.hpp"
#include "core/tick.hpp"

namespace l6470emu {

/// Which engine advances a chip's motion.
enum class MotionEngine : std::uint8_t {
  fast,       ///< event-driven, closed form (default)
  reference,  ///< tick by tick; defines the semantics
};

/// Ticks from now during which every tick follows one uniform rule (speed changes by a
/// constant, nothing ends, no decision is taken); kNever when that lasts for ever.
/// The tick after them is a boundary tick that reference_tick() performs.
Tick uniform_ticks(const MotionState& s, const Profile& p, Tick limit);

/// Applies `n` uniform ticks (n <= uniform_ticks()) in closed form.
void apply_uniform_ticks(MotionState& s, const Profile& p, Tick n);

/// The speed apply_uniform_ticks(s, p, n) would leave, without working the rest out.
std::uint64_t speed_after_uniform_ticks(const MotionState& s, const Profile& p, Tick n);
/// The first i in 1..n (n <= uniform_ticks()) after which speed_after_uniform_ticks(s, p, i) is
/// at least `speed` (`up`) or below it (!up), n + 1 when there is none: solved, not searched.
/// (The speed moves one way through uniform ticks; asked the other way, it is searched.)
Tick first_uniform_tick_at_speed(const MotionState& s, const Profile& p, std::uint64_t speed, bool up, Tick n);
/// The first i in 1..n (n <= uniform_ticks()) after which travel_after_uniform_ticks(s, p, i) has
/// reached `travel` going the motor's way (at or beyond it), n + 1 when it does not: solved at
/// constant speed, searched on a ramp.
Tick first_uniform_tick_at_travel(const MotionState& s, const Profile& p, std::int64_t travel, Tick n);
/// The travel (1/128 step) apply_uniform_ticks(s, p, n) would leave, without working the rest out.
std::int64_t travel_after_uniform_ticks(const MotionState& s, const Profile& p, Tick n);

/// What the event-driven engine remembers between calls: how many uniform ticks are left
/// from the current state. Forget it (known = false) whenever the state or the profile is
/// changed by anything but the passage of time.
struct UniformRun {
  Tick left = 0;
  bool known = false;
};

/// Advances by `ticks` ticks with the event-driven engine; identical to reference_advance().
/// Returns true when a boundary tick was crossed (MOT_STATUS, BUSY and the like may have changed).
bool fast_advance(MotionState& s, const Profile& p, Tick ticks, UniformRun& run);

/// The same without remembering anything between calls.
inline void fast_advance(MotionState& s, const Profile& p, Tick ticks) {
  UniformRun run;
  fast_advance(s, p, ticks, run);
}

}  // namespace l6470emu
