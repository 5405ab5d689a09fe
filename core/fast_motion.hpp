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

/// Advances by `ticks` ticks with the event-driven engine; identical to reference_advance().
void fast_advance(MotionState& s, const Profile& p, Tick ticks);

/// Advances with the chosen engine.
inline void motion_advance(MotionEngine e, MotionState& s, const Profile& p, Tick ticks) {
  if (e == MotionEngine::fast)
    fast_advance(s, p, ticks);
  else
    reference_advance(s, p, ticks);
}

}  // namespace l6470emu
