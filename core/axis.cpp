// The axis rules (docs/chip-model.md, "The mechanical world") and the search for the tick of
// the next mechanical event inside a run of uniform ticks, which keeps the event-driven engine
// identical to the tick-by-tick one: every decision of settle() depends on the speed band, the
// true position or the time, and each of those moves monotonically through a uniform run.
#include "core/axis.hpp"

#include <algorithm>

#include "core/fast_motion.hpp"
#include "core/first_true.hpp"

namespace l6470emu {
namespace {

constexpr std::int64_t kHalfCycle = 256;  // two full steps, 1/128 step
constexpr std::int64_t kCycle = 512;      // one electrical cycle

std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  std::int64_t q = a / b;
  if ((a % b != 0) && ((a < 0) != (b < 0))) --q;
  return q;
}

bool moving(const MotionState& s) { return motion_active(s) && !s.hiz; }

}  // namespace

DrivePhase drive_phase(const MotionState& s, const Profile& p) {
  switch (mot_status(s, p)) {
    case MotStatus::stopped: return DrivePhase::hold;
    case MotStatus::acceleration: return DrivePhase::acc;
    case MotStatus::deceleration: return DrivePhase::dec;
    case MotStatus::constant_speed: return DrivePhase::run;
  }
  return DrivePhase::hold;
}

Axis::Axis(AxisSpec spec, std::int64_t travel)
    : spec_(std::move(spec)), cmd0_(travel), cmd_(travel) {
  offset_ = spec_.start_position - travel;
  true_pos_ = clamp(travel + offset_);
  switches_.resize(spec_.switches.size());
  for (std::size_t i = 0; i < switches_.size(); ++i) {
    const SwitchSpec& sw = spec_.switches[i];
    bouncing_ = bouncing_ || (sw.bounce_count > 0 && sw.bounce_ticks > 0);
    switches_[i].actuated = sw.above ? true_pos_ >= sw.position : true_pos_ <= sw.position;
    switches_[i].shown_closed = switches_[i].actuated != sw.normally_closed;
    if (switches_[i].shown_closed) sw_level_ = false;
  }
}

void Axis::set_load(const LoadSpec& load) {
  if (spec_.load == load) return;
  spec_.load = load;
  forget_table();
}

void Axis::set_stops(bool has_lower, std::int64_t lower, bool has_upper, std::int64_t upper) {
  spec_.has_lower_stop = has_lower;
  spec_.lower_stop = lower;
  spec_.has_upper_stop = has_upper;
  spec_.upper_stop = upper;
  table_.clear();
}

void Axis::set_supply(std::uint32_t supply_mV) {
  if (spec_.supply.supply_mV == supply_mV) return;
  spec_.supply.supply_mV = supply_mV;
  table_.clear();
}

void Axis::set_drive(const DriveInputs& drive) {
  if (drive_ == drive) return;
  drive_ = drive;
  forget_table();
}

void Axis::forget_table() {
  table_.clear();
  band_runs_.fill(BandRun{});
}

std::int64_t Axis::clamp(std::int64_t u) const {
  if (spec_.has_upper_stop && u > spec_.upper_stop) return spec_.upper_stop;
  if (spec_.has_lower_stop && u < spec_.lower_stop) return spec_.lower_stop;
  return u;
}

std::uint8_t Axis::compute_entry(DrivePhase phase, bool forward, std::uint32_t band) const {
  if (table_.empty()) table_.assign(std::size_t{8} * kSpeedBands, 0xFF);
  std::uint8_t& e = table_[(static_cast<std::size_t>(phase) * 2 + (forward ? 1 : 0)) * kSpeedBands + band];
  if (e != 0xFF) return e;
  const DrivePoint d = drive_point(spec_, drive_, phase, band);
  const std::uint64_t need = l6470emu::required_torque_uNm(spec_, drive_, phase, forward);
  const std::uint32_t rds = spec_.supply.rds_on_mohm;
  std::uint8_t v = 0;
  if (d.torque_uNm < need) v |= kLost;
  if (comparator_trips(drive_.stall_kind, drive_.stall_th, d.sync_mA, rds)) v |= kStallSync;
  if (comparator_trips(drive_.ocd_kind, drive_.ocd_th, d.sync_mA, rds)) v |= kOcdSync;
  if (comparator_trips(drive_.stall_kind, drive_.stall_th, d.blocked_mA, rds)) v |= kStallBlocked;
  if (comparator_trips(drive_.ocd_kind, drive_.ocd_th, d.blocked_mA, rds)) v |= kOcdBlocked;
  // band speed b·15625/1024 step/s at or below the pull-in speed
  if (std::uint64_t{band} * 15625 <= std::uint64_t{spec_.pull_in_speed_steps_per_s} * 1024) v |= kPullIn;
  e = v;
  return e;
}

bool Axis::shown(const SwitchSpec& sw, const SwitchState& st, Tick now) const {
  bool closed = st.actuated != sw.normally_closed;
  if (sw.bounce_count > 0 && sw.bounce_ticks > 0 && st.ever_changed && now >= st.changed_at) {
    const Tick j = (now - st.changed_at) / sw.bounce_ticks;
    if (j < Tick{2} * sw.bounce_count && (j & 1)) closed = !closed;
  }
  return closed;
}

void Axis::observe(const MotionState& s, const Profile& p) {
  cmd_ = s.travel;
  true_pos_ = synced_ ? clamp(cmd_ + offset_) : stall_pos_;
  const DrivePhase phase = drive_phase(s, p);
  const DrivePoint d = drive_point(spec_, drive_, phase, speed_band(s.speed));
  current_mA_ = s.hiz ? 0 : (synced_ ? d.sync_mA : d.blocked_mA);
  torque_avail_ = s.hiz ? 0 : d.torque_uNm;
  torque_req_ = moving(s) ? l6470emu::required_torque_uNm(spec_, drive_, phase, s.dir) : 0;
}

bool Axis::settle(const MotionState& s, const Profile& p, Tick now) {
  const bool was_synced = synced_;
  const std::int64_t was_at = synced_ ? offset_ : stall_pos_;
  const bool is_moving = moving(s);
  const DrivePhase phase = drive_phase(s, p);
  const std::uint8_t e = entry(phase, s.dir, speed_band(s.speed));
  const std::int64_t cmd = s.travel;
  settled_at_ = now;

  if (!synced_ && (!is_moving || ((e & kPullIn) && !(e & kLost)))) {
    // Pull in: the nearest rotor position with the commanded electrical phase.
    const std::int64_t phase0 = spec_.start_position - cmd0_;  // true − commanded when attached
    offset_ = phase0 + kCycle * floor_div(stall_pos_ - cmd - phase0 + kHalfCycle, kCycle);
    synced_ = true;
  }
  if (synced_) {
    const std::int64_t u = cmd + offset_;
    if (is_moving && (e & kLost)) {
      synced_ = false;
      stall_pos_ = clamp(u);
    } else if (spec_.has_upper_stop && u > spec_.upper_stop &&
               ((is_moving && s.dir) || u > spec_.upper_stop + kHalfCycle)) {
      synced_ = false;
      stall_pos_ = spec_.upper_stop;
    } else if (spec_.has_lower_stop && u < spec_.lower_stop &&
               ((is_moving && !s.dir) || u < spec_.lower_stop - kHalfCycle)) {
      synced_ = false;
      stall_pos_ = spec_.lower_stop;
    }
  }
  bool changed = synced_ != was_synced || (synced_ ? offset_ : stall_pos_) != was_at;
  cmd_ = cmd;
  true_pos_ = synced_ ? clamp(cmd_ + offset_) : stall_pos_;

  bool level = true;
  for (std::size_t i = 0; i < switches_.size(); ++i) {
    const SwitchSpec& sw = spec_.switches[i];
    SwitchState& st = switches_[i];
    bool act = st.actuated;
    if (!sw.above) {
      if (!act && true_pos_ <= sw.position) act = true;
      else if (act && true_pos_ > sw.position + sw.hysteresis) act = false;
    } else {
      if (!act && true_pos_ >= sw.position) act = true;
      else if (act && true_pos_ < sw.position - sw.hysteresis) act = false;
    }
    if (act != st.actuated) {
      st.actuated = act;
      st.ever_changed = true;
      st.changed_at = now;
      changed = true;
    }
    const bool closed = shown(sw, st, now);
    if (closed != st.shown_closed) {
      st.shown_closed = closed;
      changed = true;
    }
    if (closed) level = false;
  }
  const bool stall = is_moving && (e & (synced_ ? kStallSync : kStallBlocked)) != 0;
  const bool ocd = !s.hiz && (e & (synced_ ? kOcdSync : kOcdBlocked)) != 0;
  changed = changed || level != sw_level_ || stall != stall_ || ocd != ocd_;
  sw_level_ = level;
  stall_ = stall;
  ocd_ = ocd;
  return changed;
}

Tick Axis::next_time_event() const {
  Tick next = kNever;
  if (!bouncing_) return next;
  for (std::size_t i = 0; i < switches_.size(); ++i) {
    const SwitchSpec& sw = spec_.switches[i];
    const SwitchState& st = switches_[i];
    if (sw.bounce_count == 0 || sw.bounce_ticks == 0 || !st.ever_changed) continue;
    // Edges at changed_at + j·T for j = 1 .. 2·bounce_count; the next one after the last settle.
    const Tick last_edge = st.changed_at + Tick{2} * sw.bounce_count * sw.bounce_ticks;
    if (last_edge <= settled_at_) continue;
    const Tick j = (settled_at_ - st.changed_at) / sw.bounce_ticks + 1;
    next = std::min(next, st.changed_at + j * sw.bounce_ticks);
  }
  return next;
}

std::uint32_t Axis::first_other_band(DrivePhase phase, bool forward, std::uint32_t b0, std::uint32_t bn) const {
  // The run of bands around b0 whose signature is b0's, as far as earlier searches found it.
  BandRun& run = band_runs_[(static_cast<std::size_t>(phase) * 2 + (forward ? 1 : 0)) * 2 + (synced_ ? 1 : 0)];
  if (!(run.lo <= b0 && b0 <= run.hi)) run = {static_cast<std::uint16_t>(b0), static_cast<std::uint16_t>(b0)};
  const std::uint8_t sig0 = signature(entry(phase, forward, b0), true);
  if (bn > b0) {
    while (run.hi < bn && signature(entry(phase, forward, run.hi + 1u), true) == sig0) ++run.hi;
    return run.hi < bn ? run.hi + 1u : bn + 1;
  }
  while (run.lo > bn && signature(entry(phase, forward, run.lo - 1u), true) == sig0) --run.lo;
  return run.lo > bn ? run.lo - 1u : bn - 1;
}

Tick Axis::first_event(const MotionState& s, const Profile& p, Tick n, Tick now) const {
  Tick best = n + 1;
  const Tick timed = next_time_event();
  if (timed != kNever && timed > now && timed - now <= n) best = timed - now;
  if (!moving(s) || best == 1) return best;
  const Tick m = best - 1;  // only ticks before the best event so far matter

  // A change of speed band that changes what settle() would decide.
  const DrivePhase phase = drive_phase(s, p);
  const std::uint32_t b0 = speed_band(s.speed);
  const std::uint64_t vm = speed_after_uniform_ticks(s, p, m);
  const std::uint32_t bn = speed_band(vm);
  if (bn != b0) {
    const bool up = bn > b0;
    const std::uint32_t b = first_other_band(phase, s.dir, b0, bn);
    if (b != bn + (up ? 1 : -1)) {
      // Band b begins at b * 2^22 (2^-40 step/tick); below band b + 1 is speed_band() <= b.
      const std::uint64_t edge = std::uint64_t{up ? b : b + 1} << 22;
      best = std::min(best, first_uniform_tick_at_speed(s, p, edge, up, m));
    }
  }

  // The true position reaching a hard stop or a switch's actuation or release point.
  if (synced_ && best > 1) {
    const std::int64_t u = s.travel + offset_;
    const bool fwd = s.dir;
    bool have = false;
    std::int64_t target = 0;  // the value of u at which something happens
    auto consider = [&](std::int64_t t) {
      if (fwd ? t <= u : t >= u) return;
      if (!have || (fwd ? t < target : t > target)) target = t;
      have = true;
    };
    if (fwd && spec_.has_upper_stop) consider(spec_.upper_stop + 1);
    if (!fwd && spec_.has_lower_stop) consider(spec_.lower_stop - 1);
    for (std::size_t i = 0; i < switches_.size(); ++i) {
      const SwitchSpec& sw = spec_.switches[i];
      const bool act = switches_[i].actuated;
      if (!sw.above) {
        if (fwd && act) consider(sw.position + sw.hysteresis + 1);
        if (!fwd && !act) consider(sw.position);
      } else {
        if (fwd && !act) consider(sw.position);
        if (!fwd && act) consider(sw.position - sw.hysteresis - 1);
      }
    }
    // The speed through the run lies between s.speed and vm, so in best - 1 ticks the motor
    // travels at most this far (1/128 step): a goal beyond it is not reached, nothing to search.
    const unsigned __int128 reach =
        ((static_cast<unsigned __int128>(s.frac) + static_cast<unsigned __int128>(best - 1) * std::max(s.speed, vm)) >>
         (40 - p.step_sel)) * p.el_increment();
    if (have && reach >= static_cast<unsigned __int128>(fwd ? target - u : u - target)) {
      const std::int64_t goal = target - offset_;  // commanded travel at which it happens
      best = std::min(best, first_uniform_tick_at_travel(s, p, goal, best - 1));
    }
  }
  return best;
}

}  // namespace l6470emu
