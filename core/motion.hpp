// The speed-profile generator: motion state, the profile derived from the
// registers, the commands that start or stop motion, and the tick-by-tick
// reference engine that defines the semantics (docs/motion-rules.md).
// It does not know SPI, pins or STATUS encoding; Chip wires those up.
#pragma once

#include <cstdint>

#include "core/tick.hpp"

namespace l6470emu {

/// Motion units: speeds in 2^-40 step/tick, accelerations in 2^-40 step/tick²,
/// distances in 2^-40 step (a full step is 2^40). SPEED register = speed >> 12.
namespace motion_units {
inline constexpr unsigned kFractionBits = 40;
/// ReleaseSW's floor speed, 5 step/s, rounded to the nearest 2^-40 step/tick.
inline constexpr std::uint64_t kReleaseSwFloor = 1'374'390;
}  // namespace motion_units

/// The speed profile as the registers set it, converted to motion units.
struct Profile {
  std::uint64_t acc = 0;        ///< ACC, 2^-40 step/tick²
  std::uint64_t dec = 0;        ///< DEC, 2^-40 step/tick²
  std::uint64_t max_speed = 0;  ///< MAX_SPEED << 22
  std::uint64_t min_speed = 0;  ///< MIN_SPEED bits 11:0 << 16 (the register value, LSPD_OPT aside)
  bool lspd_opt = false;        ///< MIN_SPEED bit 12: the profile's minimum speed is 0
  bool infinite = false;        ///< ACC = 0xFFF on a variant with infinite acceleration
  std::uint8_t step_sel = 7;    ///< STEP_MODE.STEP_SEL

  /// Length of one microstep of the selected mode, in 2^-40 step.
  constexpr std::uint64_t microstep() const { return std::uint64_t{1} << (40 - step_sel); }
  /// EL_POS increment of one microstep (EL_POS counts 1/128 step).
  constexpr std::uint16_t el_increment() const { return static_cast<std::uint16_t>(128u >> step_sel); }
  /// The profile's minimum speed: where ramps start and end.
  constexpr std::uint64_t floor_speed() const {
    const std::uint64_t v = lspd_opt ? 0 : min_speed;
    return v < max_speed ? v : max_speed;
  }
  /// Speed of ReleaseSW: MIN_SPEED, but at least 5 step/s (always 5 step/s with LSPD_OPT).
  constexpr std::uint64_t release_sw_speed() const {
    std::uint64_t v = lspd_opt ? motion_units::kReleaseSwFloor
                               : (min_speed < motion_units::kReleaseSwFloor ? motion_units::kReleaseSwFloor : min_speed);
    return v < max_speed ? v : max_speed;
  }
};

/// What the generator is doing.
enum class Activity : std::uint8_t {
  idle,        ///< stopped (bridges enabled or not)
  run,         ///< Run: track a target speed
  go_until,    ///< GoUntil: track a target speed until a switch turn-on event
  release_sw,  ///< ReleaseSW: run at the ReleaseSW speed until the switch opens
  position,    ///< Move, GoTo, GoTo_DIR, GoHome, GoMark
  stopping,    ///< SoftStop / SoftHiZ: decelerate to the minimum speed, then stop
  step_clock,  ///< step-clock mode: STCK edges move the motor
};

/// MOT_STATUS values.
enum class MotStatus : std::uint8_t { stopped = 0, acceleration = 1, deceleration = 2, constant_speed = 3 };

/// The generator's whole state. Positions use the selected step mode's units.
struct MotionState {
  Activity activity = Activity::idle;
  bool dir = false;            ///< current direction, true = forward (power-up: reverse)
  bool target_dir = false;     ///< direction to take once a reversal has slowed down
  bool reversing = false;      ///< slowing to the minimum speed before turning round
  bool braking = false;        ///< positioning: deceleration phase has begun (sticky)
  bool hiz_after_stop = false; ///< SoftHiZ: disable the bridges once stopped
  bool hiz = true;             ///< bridges in high impedance
  std::uint64_t speed = 0;     ///< current speed, 2^-40 step/tick
  std::uint64_t frac = 0;      ///< progress toward the next microstep, 2^-40 step
  std::uint64_t run_speed = 0; ///< Run/GoUntil SPD in 2^-40 step/tick, before clamping
  std::uint32_t steps_left = 0;///< positioning: microsteps still to make
  std::int32_t target_pos = 0; ///< positioning target, used when a reversal completes
  std::int32_t abs_pos = 0;    ///< ABS_POS, sign-extended 22-bit
  std::uint16_t el_pos = 0;    ///< EL_POS, 9 bits
  /// Commanded travel since the chip was made, 1/128 step, never wrapped or reset (the
  /// mechanical axis follows it; ResetPos, ABS_POS writes and resets leave it alone).
  std::int64_t travel = 0;

  friend bool operator==(const MotionState&, const MotionState&) = default;
};

/// The target speed of a constant-speed activity under `p`.
std::uint64_t constant_speed_target(const MotionState& s, const Profile& p);

/// MOT_STATUS as the state implies it.
MotStatus mot_status(const MotionState& s, const Profile& p);

/// Whether a constant-speed, positioning, motion or stop command keeps BUSY low.
bool motion_busy(const MotionState& s, const Profile& p);

/// MOT_STATUS and BUSY together (what STATUS and the BUSY pin need), in one pass.
struct MotionFlags { MotStatus mot; bool busy; };
MotionFlags motion_flags(const MotionState& s, const Profile& p);

/// Whether the motor counts as stopped (Move, StepClock and WS registers accept only then).
inline bool motor_stopped(const MotionState& s) {
  return s.activity == Activity::idle || s.activity == Activity::step_clock;
}

/// Distance covered while braking from `v` to the profile floor, one tick at a time,
/// in 2^-40 step (the rule positioning uses to decide when to start decelerating).
unsigned __int128 braking_distance(std::uint64_t v, const Profile& p);

/// Commands. Each one is applied at a tick boundary; bridges leave HiZ where the chip does so.
void start_run(MotionState& s, const Profile& p, bool dir, std::uint64_t spd);
void start_go_until(MotionState& s, const Profile& p, bool dir, std::uint64_t spd);
void start_release_sw(MotionState& s, const Profile& p, bool dir);
/// Moves `steps` microsteps in `dir` (Move, GoTo family once the direction is chosen).
void start_positioning(MotionState& s, const Profile& p, bool dir, std::int32_t target, std::uint32_t steps);
void start_step_clock(MotionState& s, bool dir);
void soft_stop(MotionState& s, const Profile& p, bool then_hiz);
void hard_stop(MotionState& s);
void hard_hiz(MotionState& s);

/// One microstep in the current direction: ABS_POS and EL_POS move, ABS_POS wraps in 22 bits.
void take_microstep(MotionState& s, const Profile& p);
/// `n` microsteps in the current direction at once: exactly `n` take_microstep calls (ABS_POS
/// wrapped in 22 bits, EL_POS in 9, the travel summed), at a cost independent of `n`.
void take_microsteps(MotionState& s, const Profile& p, std::uint64_t n);

/// GoTo's shortest path from `from` to `to` in 22-bit space: direction (true = forward) and distance.
/// A distance of exactly 2^21 goes in reverse (the sign of the 22-bit difference).
struct Path { bool forward; std::uint32_t steps; };
Path shortest_path(std::int32_t from, std::int32_t to);
/// Distance from `from` to `to` going in `forward`'s direction, in 22-bit space.
std::uint32_t directed_distance(std::int32_t from, std::int32_t to, bool forward);

/// Advances the reference engine by exactly one tick.
void reference_tick(MotionState& s, const Profile& p);

/// Advances the reference engine by `ticks` ticks (idle and step-clock cost nothing).
void reference_advance(MotionState& s, const Profile& p, Tick ticks);

/// Whether the state changes on its own as time passes.
inline bool motion_active(const MotionState& s) { return !motor_stopped(s); }

}  // namespace l6470emu
