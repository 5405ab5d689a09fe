// The mechanical axis behind one chip: where the rotor truly is, whether it follows the
// commanded motion or has lost synchronism, hard stops, switches on SW, and the stall and
// overcurrent conditions the phase current raises. Pure computation on the chip's ticks;
// Chip calls it after every tick it performs and asks it where its next event is.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/axis_spec.hpp"
#include "core/drive_model.hpp"
#include "core/motion.hpp"
#include "core/tick.hpp"

namespace l6470emu {

/// The state of one axis. Rules (docs/chip-model.md, "The mechanical world"):
/// while synchronised the rotor is at the commanded position plus a whole number of electrical
/// cycles, clamped by the hard stops; it loses synchronism when the torque the profile needs
/// exceeds what the drive gives at the speed, or when the commanded position runs into a hard
/// stop; it then stands still until the commanded motion stops (or slows to the pull-in
/// speed) and snaps to the nearest rotor position with the commanded electrical phase.
class Axis {
 public:
  /// An axis at `spec.start_position`, synchronised with the chip's commanded travel `travel`.
  Axis(AxisSpec spec, std::int64_t travel);

  const AxisSpec& spec() const { return spec_; }

  // ---- observations (as of the last observe(); Chip::axis() calls it) ------------------

  /// The rotor's true position, 1/128 step.
  std::int64_t true_position() const { return true_pos_; }
  /// Commanded travel since the axis was attached minus true travel, 1/128 step (a multiple
  /// of 512 once re-synchronised, unless the rotor is pressed against a hard stop).
  std::int64_t lost_steps() const { return cmd_ - cmd0_ - (true_pos_ - spec_.start_position); }
  /// Whether the rotor follows the commanded motion.
  bool synchronised() const { return synced_; }
  /// Whether the rotor stands at a hard stop.
  bool at_stop() const {
    return (spec_.has_lower_stop && true_pos_ == spec_.lower_stop) || (spec_.has_upper_stop && true_pos_ == spec_.upper_stop);
  }
  /// Whether switch `i` is actuated (the carriage is on it; hysteresis applied).
  bool switch_actuated(std::size_t i) const { return switches_.at(i).actuated; }
  /// Whether switch `i`'s contact is closed now (normally-closed and bounce applied).
  bool switch_closed(std::size_t i) const { return switches_.at(i).shown_closed; }
  /// The SW level the switches make: false = some contact closed (pin pulled low).
  bool sw_level() const { return sw_level_; }
  /// The stall comparator trips (STALL_TH crossed while the motor is driven to move).
  bool stall_condition() const { return stall_; }
  /// The overcurrent comparator trips (OCD_TH crossed).
  bool overcurrent_condition() const { return ocd_; }
  /// Phase current amplitude the model gives now, mA.
  std::uint32_t phase_current_mA() const { return current_mA_; }
  /// Torque the drive can give at the present speed, and the torque the profile asks for, µN·m.
  std::uint32_t available_torque_uNm() const { return torque_avail_; }
  std::uint64_t required_torque_uNm() const { return torque_req_; }

  // ---- changes from outside ---------------------------------------------------------

  /// A new load (at runtime): inertia, friction, constant force.
  void set_load(const LoadSpec& load);
  /// New hard stops (at runtime), 1/128 step; a rotor beyond a new stop is held at it.
  void set_stops(bool has_lower, std::int64_t lower, bool has_upper, std::int64_t upper);
  /// A new motor supply (at runtime), mV.
  void set_supply(std::uint32_t supply_mV);
  /// The chip's drive registers; the cached per-speed table is rebuilt when they change.
  void set_drive(const DriveInputs& drive);

  // ---- used by Chip -----------------------------------------------------------------

  /// Brings the observations up to the motion state `s` without deciding anything (between
  /// events nothing changes but the true position following the commanded one).
  void observe(const MotionState& s, const Profile& p);
  /// Applies the rules to the motion state after a tick, a command or a pin change at tick
  /// `now`. Returns whether anything observable changed (synchronism, a switch, an output).
  bool settle(const MotionState& s, const Profile& p, Tick now);
  /// For a run of `n` uniform ticks from `s` (settled at tick `now`): the first tick k in
  /// 1..n after which settle() would change something, or n + 1 when none does.
  Tick first_event(const MotionState& s, const Profile& p, Tick n, Tick now) const;
  /// The absolute tick of the next switch-bounce edge, kNever when none is pending.
  Tick next_time_event() const;

 private:
  struct SwitchState {
    bool actuated = false;
    bool shown_closed = false;
    bool ever_changed = false;
    Tick changed_at = 0;
  };
  enum Bits : std::uint8_t { kLost = 1, kStallSync = 2, kOcdSync = 4, kStallBlocked = 8, kOcdBlocked = 16, kPullIn = 32 };

  /// The Bits of (phase, direction, speed band), worked out the first time they are asked for.
  std::uint8_t entry(DrivePhase phase, bool forward, std::uint32_t band) const {
    if (!table_.empty()) {
      const std::uint8_t e = table_[(static_cast<std::size_t>(phase) * 2 + (forward ? 1 : 0)) * kSpeedBands + band];
      if (e != 0xFF) return e;
    }
    return compute_entry(phase, forward, band);
  }
  std::uint8_t compute_entry(DrivePhase phase, bool forward, std::uint32_t band) const;
  /// Moving from band b0 toward band bn (!= b0): the first band whose signature differs from
  /// b0's, or the band one past bn when none does.
  std::uint32_t first_other_band(DrivePhase phase, bool forward, std::uint32_t b0, std::uint32_t bn) const;
  void forget_table();
  /// The bits settle() acts on in the present state (synchronised or not, driven to move or not).
  std::uint8_t signature(std::uint8_t e, bool is_moving) const {
    if (synced_) return static_cast<std::uint8_t>(e & ((is_moving ? kLost | kStallSync : 0) | kOcdSync));
    const bool pull_in = (e & kPullIn) && !(e & kLost);
    return static_cast<std::uint8_t>((pull_in ? kPullIn : 0) | (e & (kStallBlocked | kOcdBlocked)));
  }
  std::int64_t clamp(std::int64_t u) const;
  bool shown(const SwitchSpec& sw, const SwitchState& st, Tick now) const;

  AxisSpec spec_;
  DriveInputs drive_{};
  mutable std::vector<std::uint8_t> table_;  // per (phase, direction, band): Bits, 0xFF = not yet computed
  /// Bands lo..hi of one (phase, direction) share one signature (synchronised or not, moving):
  /// what first_event() has learnt, so that a ramp is searched band by band once.
  struct BandRun {
    std::uint16_t lo = 1, hi = 0;  // empty
  };
  mutable std::array<BandRun, 16> band_runs_{};  // per (phase, direction, synchronised)
  std::int64_t cmd0_ = 0;     // commanded travel when attached
  std::int64_t cmd_ = 0;      // commanded travel as of the last look
  std::int64_t offset_ = 0;   // synchronised: true = clamp(cmd + offset)
  std::int64_t stall_pos_ = 0;
  std::int64_t true_pos_ = 0;
  bool synced_ = true;
  std::vector<SwitchState> switches_;
  bool bouncing_ = false;     // some switch bounces (has timed events)
  bool sw_level_ = true;
  bool stall_ = false;
  bool ocd_ = false;
  std::uint32_t current_mA_ = 0;
  std::uint32_t torque_avail_ = 0;
  std::uint64_t torque_req_ = 0;
  Tick settled_at_ = 0;       // tick of the last settle()
};

/// The drive phase of a motion state: hold when stopped, else by MOT_STATUS.
DrivePhase drive_phase(const MotionState& s, const Profile& p);

}  // namespace l6470emu
