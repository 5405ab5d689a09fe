// Closed-form jumps over uniform ticks. A uniform tick changes the speed by a
// constant delta (+ACC, -DEC or 0) and triggers nothing; after i of them the
// distance travelled is S(i) = i*v + delta*i*(i+1)/2, and since at most one
// microstep fits in a tick, the microsteps made are (frac + S(i)) / microstep.
// Boundary ticks (a ramp reaching its end, braking starting, the target being
// reached, a reversal turning round) are left to reference_tick().
#include "core/fast_motion.hpp"

#include <algorithm>

#include "core/first_true.hpp"
#include "core/registers.hpp"

namespace l6470emu {
namespace {

using u128 = unsigned __int128;

/// The rule of the next tick when it is uniform: speed delta sign and the tick at which
/// the ramp reaches its end (cap: the first non-uniform tick because of the ramp), or
/// nullopt-like `valid=false` when the next tick is a boundary tick anyway.
struct Rule {
  bool valid = false;
  int sign = 0;             ///< +1 accelerate by ACC, -1 decelerate by DEC, 0 constant
  std::uint64_t delta = 0;  ///< |speed change| per tick
  Tick cap = kNever;        ///< 1-based index of the tick that ends the ramp
};

Tick ceil_div(std::uint64_t a, std::uint64_t b) { return (a + b - 1) / b; }

/// A ramp from v toward t as approach() does it; the cap (a division) only when asked for.
Rule ramp(std::uint64_t v, std::uint64_t t, const Profile& p, bool with_cap = true) {
  Rule r;
  r.valid = true;
  if (v == t) return r;
  if (p.infinite) { r.valid = false; return r; }
  if (v < t) {
    if (p.acc == 0) return r;  // ACC = 0 would never get there: constant
    r.sign = +1;
    r.delta = p.acc;
    if (with_cap) r.cap = ceil_div(t - v, p.acc);
  } else {
    if (p.dec == 0) return r;
    r.sign = -1;
    r.delta = p.dec;
    if (with_cap) r.cap = ceil_div(v - t, p.dec);
  }
  return r;
}

/// Speed after i uniform ticks.
std::uint64_t speed_after(std::uint64_t v, const Rule& r, Tick i) {
  const u128 change = static_cast<u128>(r.delta) * i;
  return static_cast<std::uint64_t>(r.sign >= 0 ? v + change : v - change);
}

/// Distance of i uniform ticks (speeds v+delta, v+2*delta, ... v+i*delta).
u128 distance_after(std::uint64_t v, const Rule& r, Tick i) {
  const u128 base = static_cast<u128>(v) * i;
  const u128 tri = static_cast<u128>(r.delta) * i * (static_cast<u128>(i) + 1) / 2;
  return r.sign >= 0 ? base + tri : base - tri;
}

/// Uniform ticks of a ramp that ends at the cap tick, bounded by `limit`.
Tick ramp_limit(const Rule& r, Tick limit) {
  if (!r.valid) return 0;
  return r.cap == kNever ? limit : std::min(limit, r.cap - 1);
}

}  // namespace

Tick uniform_ticks(const MotionState& s, const Profile& p, Tick limit) {
  const std::uint64_t floor = p.floor_speed();
  switch (s.activity) {
    case Activity::idle:
    case Activity::step_clock:
      return limit;
    case Activity::stopping: {
      if (s.speed <= floor) return 0;
      return ramp_limit(ramp(s.speed, floor, p), limit);
    }
    case Activity::run:
    case Activity::go_until:
    case Activity::release_sw: {
      if (s.reversing) {
        if (s.speed <= floor) return 0;
        return ramp_limit(ramp(s.speed, floor, p), limit);
      }
      const std::uint64_t target = constant_speed_target(s, p);
      if (s.activity == Activity::run && target == 0) return 0;  // about to finish
      const Rule r = ramp(s.speed, target, p);
      if (!r.valid) return 0;
      return ramp_limit(r, limit);
    }
    case Activity::position: {
      if (s.reversing) {
        if (s.speed <= floor) return 0;
        return ramp_limit(ramp(s.speed, floor, p), limit);
      }
      Rule r;
      if (s.braking) {
        r = s.speed > floor ? ramp(s.speed, floor, p) : Rule{true, 0, 0, kNever};
      } else {
        r = ramp(s.speed, p.max_speed, p);
      }
      if (!r.valid) return 0;
      Tick n = ramp_limit(r, limit);
      const u128 remaining = static_cast<u128>(s.steps_left) * p.microstep() - s.frac;
      // The tick that reaches the target ends the run of uniform ticks.
      const Tick finish = first_true(1, n, [&](Tick i) { return distance_after(s.speed, r, i) >= remaining; });
      n = std::min(n, finish - 1);
      if (!s.braking && !p.infinite) {
        // Braking is decided at the start of tick k+1 from the state after k ticks;
        // braking_distance(v_k) + S(k) never decreases along a ramp toward MAX_SPEED.
        auto brakes_after = [&](Tick k) {
          const std::uint64_t v = speed_after(s.speed, r, k);
          return v > floor && braking_distance(v, p) >= remaining - distance_after(s.speed, r, k);
        };
        if (brakes_after(0)) return 0;
        n = std::min(n, first_true(1, n, brakes_after));
      }
      return n;
    }
  }
  return 0;
}

namespace {

/// The rule of the uniform ticks ahead of `s` (motion active), without the cap (as the
/// closed forms below use it: an invalid rule, never applied over a tick, reads as constant).
Rule uniform_rule(const MotionState& s, const Profile& p) {
  const std::uint64_t floor = p.floor_speed();
  switch (s.activity) {
    case Activity::stopping:
      return ramp(s.speed, floor, p, false);
    case Activity::run:
    case Activity::go_until:
    case Activity::release_sw:
      return s.reversing ? ramp(s.speed, floor, p, false) : ramp(s.speed, constant_speed_target(s, p), p, false);
    case Activity::position:
      if (s.reversing) return ramp(s.speed, floor, p, false);
      if (s.braking) return s.speed > floor ? ramp(s.speed, floor, p, false) : Rule{true, 0, 0, kNever};
      return ramp(s.speed, p.max_speed, p, false);
    default:
      return Rule{};
  }
}

/// Microsteps made by n uniform ticks under `r`, and the fraction of a microstep left.
struct Steps {
  u128 steps;
  std::uint64_t frac;
};
Steps steps_after(const MotionState& s, const Profile& p, const Rule& r, Tick n) {
  const u128 total = s.frac + distance_after(s.speed, r, n);
  const unsigned shift = 40u - p.step_sel;  // a microstep is 2^shift
  return {total >> shift, static_cast<std::uint64_t>(total) & (p.microstep() - 1)};
}

/// Travel (1/128 step) of `steps` microsteps in the current direction.
std::int64_t travel_of(const MotionState& s, const Profile& p, u128 steps) {
  const std::int64_t moved = static_cast<std::int64_t>(steps) * p.el_increment();
  return s.dir ? moved : -moved;
}

}  // namespace

void apply_uniform_ticks(MotionState& s, const Profile& p, Tick n) {
  if (n == 0 || !motion_active(s)) return;
  const Rule r = uniform_rule(s, p);
  const Steps made = steps_after(s, p, r, n);
  const u128 steps = made.steps;
  s.frac = made.frac;
  s.speed = speed_after(s.speed, r, n);
  if (steps == 0) return;
  const std::uint32_t mod22 = static_cast<std::uint32_t>(steps & 0x3FFFFF);
  const std::uint32_t mod512 = static_cast<std::uint32_t>(steps & 0x1FF);
  const std::uint32_t pos = static_cast<std::uint32_t>(s.abs_pos) + (s.dir ? mod22 : 0x400000u - mod22);
  s.abs_pos = sign_extend(pos & 0x3FFFFF, 22);
  const std::uint32_t el = mod512 * p.el_increment();
  s.el_pos = static_cast<std::uint16_t>((s.el_pos + (s.dir ? el : 512u * 128u - el)) & 0x1FF);
  s.travel += travel_of(s, p, steps);
  if (s.activity == Activity::position && !s.reversing) s.steps_left -= static_cast<std::uint32_t>(steps);
}

std::uint64_t speed_after_uniform_ticks(const MotionState& s, const Profile& p, Tick n) {
  if (n == 0 || !motion_active(s)) return s.speed;
  return speed_after(s.speed, uniform_rule(s, p), n);
}

Tick first_uniform_tick_at_speed(const MotionState& s, const Profile& p, std::uint64_t speed, bool up, Tick n) {
  // After i uniform ticks the speed is v + i*delta (sign +1), v - i*delta (sign -1) or v (0),
  // exactly as speed_after() computes it; solved for the first i in 1..n.
  const Rule r = motion_active(s) ? uniform_rule(s, p) : Rule{};
  const std::uint64_t v = s.speed;
  Tick i = n + 1;  // none
  if (up) {  // the first i with speed_i >= speed; the speed does not fall
    if (r.sign < 0 && r.delta != 0) return first_true(1, n, [&](Tick k) { return speed_after(v, r, k) >= speed; });
    if (v + r.delta >= speed) i = 1;
    else if (r.delta != 0) i = ceil_div(speed - v, r.delta);
  } else {  // the first i with speed_i < speed; the speed does not rise
    if (r.sign > 0 && r.delta != 0) return first_true(1, n, [&](Tick k) { return speed_after(v, r, k) < speed; });
    if (v - r.delta < speed) i = 1;  // (delta <= v - floor: no wrap)
    else if (r.delta != 0) i = (v - speed) / r.delta + 1;
  }
  return i > n ? n + 1 : i;
}

Tick first_uniform_tick_at_travel(const MotionState& s, const Profile& p, std::int64_t travel, Tick n) {
  const Rule r = motion_active(s) ? uniform_rule(s, p) : Rule{};
  const auto reached = [&](Tick i) {
    const std::int64_t t = travel_after_uniform_ticks(s, p, i);
    return s.dir ? t >= travel : t <= travel;
  };
  if (r.delta != 0) return first_true(1, n, reached);  // a ramp: searched
  // Constant speed v: after i ticks the microsteps made are (frac + i*v) >> shift, each moving
  // the travel by el_increment() in the motor's direction; solved for the first i.
  const std::int64_t gap = s.dir ? travel - s.travel : s.travel - travel;
  if (gap <= 0) return n >= 1 ? 1 : n + 1;
  const std::uint64_t el = p.el_increment();
  const u128 steps = (static_cast<std::uint64_t>(gap) + el - 1) / el;  // microsteps needed
  const u128 need = (steps << (40u - p.step_sel)) - s.frac;              // distance, 2^-40 step
  if (s.speed == 0) return n + 1;
  const u128 i = (need + s.speed - 1) / s.speed;
  return i > n ? n + 1 : static_cast<Tick>(i);
}

std::int64_t travel_after_uniform_ticks(const MotionState& s, const Profile& p, Tick n) {
  if (n == 0 || !motion_active(s)) return s.travel;
  return s.travel + travel_of(s, p, steps_after(s, p, uniform_rule(s, p), n).steps);
}

bool fast_advance(MotionState& s, const Profile& p, Tick ticks, UniformRun& run) {
  bool boundary = false;
  while (ticks > 0 && motion_active(s)) {
    if (!run.known) {
      run.left = uniform_ticks(s, p, kNever - 1);
      run.known = true;
    }
    const Tick n = std::min(run.left, ticks);
    apply_uniform_ticks(s, p, n);
    run.left -= n;
    ticks -= n;
    if (ticks == 0) break;
    reference_tick(s, p);
    --ticks;
    run.known = false;
    boundary = true;
  }
  return boundary;
}

}  // namespace l6470emu
