// The tick-by-tick reference engine. Every rule here is written down in
// docs/motion-rules.md; a faster engine must reproduce it exactly.
#include "core/motion.hpp"

#include <algorithm>

namespace l6470emu {
namespace {

constexpr std::int32_t kPosMask = 0x3FFFFF;

std::int32_t wrap22(std::int64_t v) {
  return static_cast<std::int32_t>(((v & kPosMask) ^ 0x200000) - 0x200000);
}

/// One tick of a ramp from v toward `target`, with ACC upward and DEC downward.
std::uint64_t approach(std::uint64_t v, std::uint64_t target, const Profile& p) {
  if (p.infinite) return target;
  if (v < target) return std::min(v + p.acc, target);
  if (v > target) return v - target > p.dec ? v - p.dec : target;
  return v;
}

/// Adds one tick of travel at speed v; returns true when a microstep was made.
bool travel(MotionState& s, std::uint64_t v, const Profile& p) {
  s.frac += v;
  if (s.frac < p.microstep()) return false;
  s.frac -= p.microstep();
  take_microstep(s, p);
  return true;
}

void finish(MotionState& s) {
  s.activity = Activity::idle;
  s.speed = 0;
  s.frac = 0;
  s.reversing = false;
  s.braking = false;
  if (s.hiz_after_stop) s.hiz = true;
  s.hiz_after_stop = false;
}

/// Starts turning round: slow down to the floor, or turn at once when already there.
void begin_direction(MotionState& s, const Profile& p, bool dir) {
  const bool moving = s.activity != Activity::idle && s.activity != Activity::step_clock && s.speed > 0;
  if (!moving) {
    s.dir = dir;
    s.reversing = false;
    s.frac = 0;
    s.speed = p.floor_speed();
    return;
  }
  if (dir == s.dir) {
    s.reversing = false;
    return;
  }
  if (p.infinite || s.speed <= p.floor_speed()) {
    s.dir = dir;
    s.reversing = false;
    s.frac = 0;
    s.speed = p.floor_speed();
    return;
  }
  s.reversing = true;
  s.target_dir = dir;
}

void begin_constant(MotionState& s, const Profile& p, Activity a, bool dir, std::uint64_t spd) {
  s.hiz = false;
  s.hiz_after_stop = false;
  s.braking = false;
  s.run_speed = spd;
  begin_direction(s, p, dir);
  s.activity = a;
  if (p.infinite && !s.reversing) s.speed = constant_speed_target(s, p);
}

/// The tick in which a reversal reaches the floor: the motor turns round.
bool reversal_tick(MotionState& s, const Profile& p) {
  const std::uint64_t floor = p.floor_speed();
  if (s.speed > floor) s.speed = approach(s.speed, floor, p);
  travel(s, s.speed, p);
  if (s.speed > floor) return false;
  s.dir = s.target_dir;
  s.reversing = false;
  s.frac = 0;
  return true;
}

}  // namespace

std::uint64_t constant_speed_target(const MotionState& s, const Profile& p) {
  if (s.activity == Activity::release_sw) return p.release_sw_speed();
  std::uint64_t t = std::max(s.run_speed, p.floor_speed());
  return std::min(t, p.max_speed);
}

MotStatus mot_status(const MotionState& s, const Profile& p) {
  switch (s.activity) {
    case Activity::idle:
    case Activity::step_clock:
      return MotStatus::stopped;
    case Activity::stopping:
      return MotStatus::deceleration;
    case Activity::run:
    case Activity::go_until:
    case Activity::release_sw: {
      if (s.reversing) return MotStatus::deceleration;
      const std::uint64_t t = constant_speed_target(s, p);
      if (s.speed < t) return MotStatus::acceleration;
      if (s.speed > t) return MotStatus::deceleration;
      return MotStatus::constant_speed;
    }
    case Activity::position:
      if (s.reversing) return MotStatus::deceleration;
      if (s.braking) return s.speed > p.floor_speed() ? MotStatus::deceleration : MotStatus::constant_speed;
      if (s.speed < p.max_speed && !p.infinite) return MotStatus::acceleration;
      if (s.speed > p.max_speed) return MotStatus::deceleration;
      return MotStatus::constant_speed;
  }
  return MotStatus::stopped;
}

MotionFlags motion_flags(const MotionState& s, const Profile& p) {
  const MotStatus mot = mot_status(s, p);
  // A Run keeps BUSY low until it cruises at its target; every other activity until it ends.
  const bool busy = s.activity == Activity::run ? mot != MotStatus::constant_speed : !motor_stopped(s);
  return {mot, busy};
}

bool motion_busy(const MotionState& s, const Profile& p) { return motion_flags(s, p).busy; }

unsigned __int128 braking_distance(std::uint64_t v, const Profile& p) {
  const std::uint64_t f = p.floor_speed();
  if (v <= f || p.dec == 0) return 0;
  const std::uint64_t n = (v - f + p.dec - 1) / p.dec;  // ticks until the floor is reached
  using u128 = unsigned __int128;
  const u128 m = n - 1;
  return m * v - static_cast<u128>(p.dec) * m * n / 2 + f;
}

void start_run(MotionState& s, const Profile& p, bool dir, std::uint64_t spd) {
  begin_constant(s, p, Activity::run, dir, spd);
}

void start_go_until(MotionState& s, const Profile& p, bool dir, std::uint64_t spd) {
  begin_constant(s, p, Activity::go_until, dir, spd);
}

void start_release_sw(MotionState& s, const Profile& p, bool dir) {
  const bool was_stopped = motor_stopped(s) || s.speed == 0;
  begin_constant(s, p, Activity::release_sw, dir, 0);
  // From standstill ReleaseSW starts right at its speed; it ramps only from motion.
  if (was_stopped) s.speed = p.release_sw_speed();
}

void start_positioning(MotionState& s, const Profile& p, bool dir, std::int32_t target, std::uint32_t steps) {
  s.hiz = false;
  s.hiz_after_stop = false;
  s.braking = false;
  s.target_pos = target;
  begin_direction(s, p, dir);
  s.activity = Activity::position;
  s.steps_left = s.reversing ? 0 : steps;
  if (!s.reversing && steps == 0) {
    finish(s);
    return;
  }
  if (p.infinite && !s.reversing) s.speed = p.max_speed;
}

void start_step_clock(MotionState& s, bool dir) {
  s.hiz = false;
  s.hiz_after_stop = false;
  s.activity = Activity::step_clock;
  s.dir = dir;
  s.speed = 0;
  s.frac = 0;
  s.reversing = false;
  s.braking = false;
}

void soft_stop(MotionState& s, const Profile& p, bool then_hiz) {
  if (motor_stopped(s) || p.infinite) {
    // Nothing to decelerate: SoftStop just holds, SoftHiZ disables the bridges.
    if (s.activity != Activity::step_clock) finish(s);
    s.hiz = then_hiz;
    return;
  }
  s.hiz = false;
  s.activity = Activity::stopping;
  s.hiz_after_stop = then_hiz;
  s.reversing = false;
  s.braking = false;
}

void hard_stop(MotionState& s) {
  if (s.activity != Activity::step_clock) {
    s.hiz_after_stop = false;
    finish(s);
  }
  s.hiz = false;
}

void hard_hiz(MotionState& s) {
  if (s.activity != Activity::step_clock) {
    s.hiz_after_stop = false;
    finish(s);
  }
  s.hiz = true;
}

void take_microstep(MotionState& s, const Profile& p) {
  const int delta = s.dir ? 1 : -1;
  s.abs_pos = wrap22(static_cast<std::int64_t>(s.abs_pos) + delta);
  s.el_pos = static_cast<std::uint16_t>((s.el_pos + (s.dir ? p.el_increment() : 512 - p.el_increment())) & 0x1FF);
  s.travel += s.dir ? p.el_increment() : -static_cast<std::int64_t>(p.el_increment());
}

void take_microsteps(MotionState& s, const Profile& p, std::uint64_t n) {
  if (n == 0) return;
  // ABS_POS lives modulo 2^22 and EL_POS modulo 2^9: only n's residues move them.
  const auto pos_steps = static_cast<std::int64_t>(n & kPosMask);
  s.abs_pos = wrap22(static_cast<std::int64_t>(s.abs_pos) + (s.dir ? pos_steps : -pos_steps));
  const std::uint64_t el = (n & 0x1FFu) * p.el_increment();
  s.el_pos = static_cast<std::uint16_t>((s.el_pos + (s.dir ? el : 512 * 128 - el)) & 0x1FF);
  const auto travel = static_cast<std::int64_t>(n) * p.el_increment();
  s.travel += s.dir ? travel : -travel;
}

std::uint32_t directed_distance(std::int32_t from, std::int32_t to, bool forward) {
  const auto d = static_cast<std::uint32_t>(forward ? to - from : from - to);
  return d & static_cast<std::uint32_t>(kPosMask);
}

Path shortest_path(std::int32_t from, std::int32_t to) {
  const std::uint32_t fwd = directed_distance(from, to, true);
  if (fwd < 0x200000u) return {true, fwd};
  return {false, (0x400000u - fwd) & static_cast<std::uint32_t>(kPosMask)};
}

void reference_tick(MotionState& s, const Profile& p) {
  switch (s.activity) {
    case Activity::idle:
    case Activity::step_clock:
      return;
    case Activity::run:
    case Activity::go_until:
    case Activity::release_sw: {
      if (s.reversing) {
        reversal_tick(s, p);
        return;
      }
      const std::uint64_t target = constant_speed_target(s, p);
      s.speed = approach(s.speed, target, p);
      travel(s, s.speed, p);
      if (s.activity == Activity::run && target == 0 && s.speed == 0) finish(s);
      return;
    }
    case Activity::position: {
      if (s.reversing) {
        if (reversal_tick(s, p)) {
          s.steps_left = directed_distance(s.abs_pos, s.target_pos, s.dir);
          if (s.steps_left == 0) finish(s);
        }
        return;
      }
      const std::uint64_t floor = p.floor_speed();
      if (!s.braking && !p.infinite && s.speed > floor) {
        const std::uint64_t remaining = std::uint64_t{s.steps_left} * p.microstep() - s.frac;
        if (braking_distance(s.speed, p) >= remaining) s.braking = true;
      }
      if (s.braking) {
        if (s.speed > floor) s.speed = approach(s.speed, floor, p);
      } else {
        s.speed = approach(s.speed, p.max_speed, p);
      }
      if (travel(s, s.speed, p) && --s.steps_left == 0) finish(s);
      return;
    }
    case Activity::stopping: {
      const std::uint64_t floor = p.floor_speed();
      if (s.speed > floor) s.speed = approach(s.speed, floor, p);
      travel(s, s.speed, p);
      if (s.speed <= floor) finish(s);
      return;
    }
  }
}

void reference_advance(MotionState& s, const Profile& p, Tick ticks) {
  for (Tick i = 0; i < ticks && motion_active(s); ++i) reference_tick(s, p);
}

}  // namespace l6470emu
