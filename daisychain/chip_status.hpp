// STATUS as a host reads it, with named flags in positive logic (true = the condition holds),
// for every variant's layout, and the direction type the host's commands take. Decoding only:
// which events set which flag is core/chip.cpp's business.
#pragma once

#include <cstdint>
#include <string>

#include "core/motion.hpp"
#include "core/status.hpp"
#include "core/status_layout.hpp"

namespace l6470emu {

/// The DIR bit of a motion command and of STATUS.
enum class Direction : std::uint8_t { reverse = 0, forward = 1 };

/// What GoUntil and ReleaseSW do with ABS_POS at the switch (the ACT bit).
enum class SwitchAction : std::uint8_t { reset_abs_pos = 0, copy_to_mark = 1 };

/// A STATUS value of one chip, decoded with that chip's layout. Active-low flags are turned
/// around: uvlo() is true while the supply is (or was) under the threshold. Latched flags read
/// as they were when the value was read (GetStatus clears them in the chip, not here).
class ChipStatus {
 public:
  /// `raw` as read from a chip whose STATUS layout is `layout` (which must outlive this value).
  ChipStatus(std::uint16_t raw, const StatusLayout& layout) : raw_(raw), layout_(&layout) {}

  /// The 16 bits as read.
  std::uint16_t raw() const { return raw_; }
  /// The bridges are in high impedance (HiZ).
  bool hiz() const { return bit(layout_->hiz); }
  /// A command is under way (BUSY is low).
  bool busy() const { return low(layout_->busy); }
  /// SW is closed now (SW_F).
  bool switch_closed() const { return bit(layout_->sw_f); }
  /// A switch turn-on event happened (SW_EVN, latched).
  bool switch_event() const { return bit(layout_->sw_evn); }
  /// The direction of the present or last motion (DIR).
  Direction direction() const { return bit(layout_->dir) ? Direction::forward : Direction::reverse; }
  /// MOT_STATUS: stopped, accelerating, decelerating or at constant speed.
  MotStatus motor_status() const {
    if (layout_->mot_status < 0) return MotStatus::stopped;  // no motion engine (the L6474)
    return static_cast<MotStatus>((raw_ >> layout_->mot_status) & 3u);
  }
  /// The last command could not be performed (NOTPERF_CMD; CMD_ERROR on the gate-driver parts).
  bool notperf_cmd() const { return bit(layout_->notperf_cmd); }
  /// The last command did not exist (WRONG_CMD; CMD_ERROR on the gate-driver parts).
  bool wrong_cmd() const { return bit(layout_->wrong_cmd); }
  /// Undervoltage lockout of the motor supply (UVLO, active low in the register).
  bool uvlo() const { return low(layout_->uvlo); }
  /// ADC undervoltage (UVLO_ADC, gate-driver parts; false where the layout has no such flag).
  bool uvlo_adc() const { return low(layout_->uvlo_adc); }
  /// The die temperature class (TH_WRN / TH_SD, or TH_STATUS on the gate-driver parts).
  Thermal thermal() const;
  /// Overcurrent (OCD, active low).
  bool overcurrent() const { return low(layout_->ocd); }
  /// Stall or step loss on bridge A / B (STEP_LOSS_A/B, STALL_A/B; active low; false on a part
  /// without stall detection).
  bool step_loss_a() const { return low(layout_->step_loss_a); }
  bool step_loss_b() const { return low(layout_->step_loss_b); }
  /// Either bridge stalled.
  bool stalled() const { return step_loss_a() || step_loss_b(); }
  /// Step-clock mode (SCK_MOD / STCK_MOD).
  bool step_clock_mode() const { return bit(layout_->sck_mod); }
  /// Any alarm that needs the host's attention: UVLO, UVLO_ADC, thermal, overcurrent, stall, a
  /// refused or unknown command.
  bool any_alarm() const {
    return uvlo() || uvlo_adc() || thermal() != Thermal::normal || overcurrent() || stalled() || notperf_cmd() ||
           wrong_cmd();
  }
  /// The notable conditions in words, e.g. "HiZ UVLO" (core's describe_status).
  std::string to_string() const { return describe_status(*layout_, raw_); }

  friend bool operator==(const ChipStatus& a, const ChipStatus& b) { return a.raw_ == b.raw_; }

 private:
  bool bit(std::int8_t at) const { return at >= 0 && ((raw_ >> at) & 1u) != 0; }
  /// An active-low field that is there and low (a field the layout lacks is never active).
  bool low(std::int8_t at) const { return at >= 0 && ((raw_ >> at) & 1u) == 0; }

  std::uint16_t raw_;
  const StatusLayout* layout_;
};

}  // namespace l6470emu
