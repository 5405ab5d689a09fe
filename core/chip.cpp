// Chip: the command decoder, register access rules, STATUS latching, pins and
// faults around the motion engine. Rules are from spec/dspin-reference.md §1-§6.
#include "core/chip.hpp"

#include <algorithm>
#include <cstdio>

namespace l6470emu {
namespace {

constexpr std::uint32_t kPosMask = 0x3FFFFF;
constexpr std::uint32_t kConfigOcSd = 1u << 7;
constexpr std::uint32_t kConfigSwMode = 1u << 4;
constexpr std::uint32_t kStepModeSyncEn = 1u << 7;

std::string hex(std::uint32_t v, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", digits, v);
  return buf;
}

}  // namespace

Chip::Chip(const Variant& variant, Quirks quirks)
    : variant_(&variant), table_(&variant), quirks_(quirks), layout_(variant.status) {
  // The stall-bit conflict concerns the gate-driver layout (stall flags on bits 14/15) only.
  if (quirks.stall_bits == StallBitOrder::a_on_15 && layout_.step_loss_a == 14 && layout_.step_loss_b == 15)
    std::swap(layout_.step_loss_a, layout_.step_loss_b);
  reset_logic();
  come_out_of_reset();
}

// ---------------------------------------------------------------- reset

void Chip::reset_logic() {
  touched();
  table_ = variant_;
  for (const auto& r : variant_->registers) regs_[r.address] = r.reset;
  drive_stale_ = true;
  const std::int64_t travel = motion_.travel;  // the shaft does not move with a reset
  motion_ = MotionState{};
  motion_.travel = travel;
  if (!variant_->motion_engine) {
    // No generator to leave: the part is always where the others are in step-clock mode.
    motion_.activity = Activity::step_clock;
    motion_.dir = dir_level_;
  }
  refresh_profile();
  set_collecting(false);
  args_seen_ = 0;
  arg_ = 0;
  response_ = 0;
  response_left_ = 0;
  ocd_shutdown_ = false;
  switch_act_ = false;
  // Any logic reset forces the UVLO flag active; ongoing faults show at once.
  latched_ = condition_;
  latched_changed();
  latched_.uvlo = true;
  latched_changed();
}

void Chip::come_out_of_reset() {
  // A switch already closed when the logic starts is seen as a turn-on event
  // (community report: the chip leaves HiZ at power-up when SW is low).
  if (!sw_level_) switch_turn_on_event();
}

// ---------------------------------------------------------------- SPI

std::uint8_t Chip::decode_byte(std::uint8_t byte) {
  ++decoded_bytes_;
  if (!stby_level_) return 0x00;
  // Commands see the motion as of now; GetStatus inside a run of uniform ticks needs only
  // the flags, which cannot have changed, so polling does not work the motion out.
  if (byte == 0xD0 && !collecting_) {  // the polling command, straight through
    if (command_sink_) command_sink_(variant_->opcodes[0xD0], 0);
    return get_status(status());
  }
  sync();
  if (collecting_) {
    arg_ = (arg_ << 8) | byte;
    if (++args_seen_ == pending_.arg_bytes) {
      set_collecting(false);
      execute(pending_, arg_);
      if (axis_) axis_after_change();
    }
    return next_response_byte();
  }
  const Opcode& op = variant_->opcodes[byte];
  switch (op.command) {
    case Command::Unknown: {
      const Command raw = classify_opcode(byte).command;
      if (raw == Command::SetParam || raw == Command::GetParam)
        wrong_command(byte, "no register at this address");
      else if (raw == Command::Unknown)
        wrong_command(byte, "no such command");
      else  // a command of the parts with a motion engine, sent to one without (the L6474)
        wrong_command(byte, ("no such command on an " + std::string(variant_->name) + " (" +
                             std::string(to_string(raw)) + " on the others)").c_str());
      break;
    }
    case Command::Reserved:
      wrong_command(byte, "reserved opcode");
      break;
    case Command::SetParam:
      if (table_->at_address(op.param)->access == Access::R &&
          quirks_.read_only_write == ReadOnlyWrite::wrong_cmd_at_command_byte) {
        wrong_command(byte, "SetParam of a read-only register", DiagnosticDetail::read_only_write);
        break;
      }
      [[fallthrough]];
    default:
      if (op.arg_bytes > 0) {
        pending_ = op;
        set_collecting(true);
        args_seen_ = 0;
        arg_ = 0;
      } else {
        execute(op, 0);
        if (axis_) axis_after_change();
      }
      break;
  }
  return next_response_byte();
}

void Chip::execute(const Opcode& op, std::uint32_t arg) {
  if (command_sink_) command_sink_(op, arg);
  // Reading commands leave the motion as it is; everything else may change it.
  if (op.command != Command::GetStatus && op.command != Command::GetParam && op.command != Command::NOP)
    touched();
  switch (op.command) {
    case Command::NOP:
      return;
    case Command::SetParam:
      exec_set_param(op.param, arg);
      return;
    case Command::GetParam: {
      const RegisterInfo& r = *table_->at_address(op.param);
      load_response(register_value(r), r.spi_bytes());
      return;
    }
    case Command::GetStatus:
      load_response(status(), 2);
      clear_status_on_get_status();
      return;
    case Command::Run:
      if (motion_command_allowed("Run")) start_run(motion_, profile_, op.dir, std::uint64_t{arg & 0xFFFFF} << 12);
      return;
    case Command::GoUntil:
      if (motion_command_allowed("GoUntil")) {
        switch_act_ = op.act;
        start_go_until(motion_, profile_, op.dir, std::uint64_t{arg & 0xFFFFF} << 12);
      }
      return;
    case Command::ReleaseSW:
      if (motion_command_allowed("ReleaseSW")) {
        switch_act_ = op.act;
        start_release_sw(motion_, profile_, op.dir);
      }
      return;
    case Command::StepClock:
      if (!motor_stopped(motion_)) return not_performable("StepClock while the motor runs", DiagnosticDetail::refused_running);
      if (motion_command_allowed("StepClock")) start_step_clock(motion_, op.dir);
      return;
    case Command::Move: {
      if (!motor_stopped(motion_)) return not_performable("Move while the motor runs", DiagnosticDetail::refused_running);
      if (!motion_command_allowed("Move")) return;
      const std::uint32_t n = arg & kPosMask;
      const std::int32_t target =
          sign_extend(static_cast<std::uint32_t>(motion_.abs_pos) + (op.dir ? n : 0u - n), 22);
      start_positioning(motion_, profile_, op.dir, target, n);
      return;
    }
    case Command::GoTo:
    case Command::GoTo_DIR:
    case Command::GoHome:
    case Command::GoMark: {
      if (motion_busy(motion_, profile_)) return not_performable("positioning command while BUSY", DiagnosticDetail::refused_busy);
      if (!motion_command_allowed(to_string(op.command).data())) return;
      std::int32_t target = 0;
      if (op.command == Command::GoTo || op.command == Command::GoTo_DIR)
        target = sign_extend(arg & kPosMask, 22);
      else if (op.command == Command::GoMark)
        target = sign_extend(reg(Reg::MARK), 22);
      if (op.command == Command::GoTo_DIR) {
        start_positioning(motion_, profile_, op.dir, target, directed_distance(motion_.abs_pos, target, op.dir));
      } else {
        const Path path = shortest_path(motion_.abs_pos, target);
        start_positioning(motion_, profile_, path.forward, target, path.steps);
      }
      return;
    }
    case Command::ResetPos:
      motion_.abs_pos = 0;
      return;
    case Command::ResetDevice:
      if (!motion_.hiz && reset_device_refused_when_enabled())
        return not_performable("ResetDevice while the bridges are enabled", DiagnosticDetail::refused_bridges_on);
      reset_logic();
      come_out_of_reset();
      return;
    case Command::SoftStop:
    case Command::SoftHiZ:
      if (hiz_forced()) {
        hard_hiz(motion_);
        return;
      }
      soft_stop(motion_, profile_, op.command == Command::SoftHiZ);
      return;
    case Command::HardStop:
    case Command::Enable:  // HardStop's opcode on the L6474, which is always in step-clock mode
      if (hiz_forced()) {
        hard_hiz(motion_);
        return;
      }
      hard_stop(motion_);
      return;
    case Command::HardHiZ:
    case Command::Disable:
      hard_hiz(motion_);
      return;
    case Command::Reserved:
    case Command::Unknown:
      return;  // rejected at the opcode byte
  }
}

bool Chip::reset_device_refused_when_enabled() const {
  switch (quirks_.reset_device) {
    case ResetDeviceWhenEnabled::variant_default: return variant_->reset_device_needs_hiz;
    case ResetDeviceWhenEnabled::performed: return false;
    case ResetDeviceWhenEnabled::refused: return true;
  }
  return false;
}

bool Chip::motion_command_allowed(const char* what) {
  if (!hiz_forced()) return true;
  std::string why = what;
  why += " while a fault holds the bridges in HiZ";
  not_performable(why.c_str(), DiagnosticDetail::refused_fault_hiz);
  return false;
}

void Chip::exec_set_param(std::uint8_t address, std::uint32_t value) {
  const RegisterInfo& r = *table_->at_address(address);
  if (r.access == Access::R) {
    std::string why = "SetParam of read-only ";
    why += r.name;
    return not_performable(why.c_str(), DiagnosticDetail::read_only_write);
  }
  value &= r.mask();
  Access access = r.access;
  if ((r.flags & kWriteConflict) != 0 && quirks_.bemf_write == BemfWriteCondition::when_stopped) access = Access::WS;
  if (access == Access::WS && !motor_stopped(motion_)) {
    std::string why = "SetParam of ";
    why += r.name;
    why += " while the motor runs";
    return not_performable(why.c_str(), DiagnosticDetail::refused_running);
  }
  if (access == Access::WH && !motion_.hiz) {
    std::string why = "SetParam of ";
    why += r.name;
    why += " while the bridges are enabled";
    return not_performable(why.c_str(), DiagnosticDetail::refused_bridges_on);
  }
  write_register(r, value);
}

void Chip::write_register(const RegisterInfo& r, std::uint32_t value) {
  switch (r.id) {
    case Reg::ABS_POS:
      motion_.abs_pos = sign_extend(value, 22);
      return;
    case Reg::EL_POS:
      motion_.el_pos = static_cast<std::uint16_t>(value);
      return;
    case Reg::STEP_MODE:
      if ((value & 7u) != (regs_[r.address] & 7u)) {
        // A new step mode restarts the electrical position at the first microstep.
        motion_.el_pos &= 0x180;
        motion_.frac = 0;
      }
      // powerSTEP01: CM_VM (bit 3) chooses the voltage- or current-mode reading of 0x09-0x10.
      if (variant_->current_mode) table_ = (value & 0x08u) ? variant_->current_mode : variant_;
      break;
    default:
      break;
  }
  regs_[r.address] = value;
  refresh_profile();
  drive_stale_ = true;
}

void Chip::refresh_profile() {
  auto reg = [&](Reg id) -> std::uint32_t {
    const RegisterInfo* r = table_->find(id);
    return r ? regs_[r->address] : 0;
  };
  const std::uint32_t acc = reg(Reg::ACC);
  profile_.acc = acc;
  profile_.dec = reg(Reg::DEC);
  profile_.max_speed = std::uint64_t{reg(Reg::MAX_SPEED)} << 22;
  const std::uint32_t min = reg(Reg::MIN_SPEED);
  profile_.min_speed = std::uint64_t{min & 0xFFF} << 16;
  profile_.lspd_opt = (min & 0x1000) != 0;
  profile_.infinite = variant_->infinite_acceleration && acc == 0xFFF;
  // Parts that stop at 1/16 run the finer STEP_SEL codes as 1/16 (UNCONFIRMED).
  profile_.step_sel = static_cast<std::uint8_t>(std::min<std::uint32_t>(reg(Reg::STEP_MODE) & 7u, variant_->max_step_sel));
}

std::uint32_t Chip::register_value(const RegisterInfo& r) const {
  switch (r.id) {
    case Reg::ABS_POS: return static_cast<std::uint32_t>(motion_.abs_pos) & kPosMask;
    case Reg::EL_POS: return motion_.el_pos;
    case Reg::SPEED: return static_cast<std::uint32_t>(motion_.speed >> 12) & r.mask();
    case Reg::ADC_OUT: return adc_code_;
    case Reg::STATUS: return status();
    default: return regs_[r.address] & r.mask();  // shared storage read at the width in force
  }
}

// ---------------------------------------------------------------- STATUS

LiveStatus Chip::live_status() const {
  LiveStatus l;
  l.hiz = motion_.hiz;
  const MotionFlags f = motion_flags(motion_, profile_);
  l.busy = f.busy;
  l.sw_closed = !sw_level_;
  l.forward = motion_.dir;
  l.step_clock = motion_.activity == Activity::step_clock;
  l.mot = f.mot;
  return l;
}

std::uint16_t Chip::status_slow() const {
  sync();
  if (!live_bits_known_) {
    live_bits_ = encode_live(layout_, live_status());
    live_bits_known_ = true;
  }
  status_word_ = static_cast<std::uint16_t>(latched_bits_ | live_bits_);
  // Cached only with nothing latched to clear, so that a GetStatus from the cache is a read.
  status_until_ = latched_clean_ && status_known_without_sync() ? status_horizon() : 0;
  return status_word_;
}

Tick Chip::status_horizon() const {
  Tick until = kNever;
  if (motion_active(motion_)) {
    // Known while now_ - motion_now_ <= run_.left; uniform ticks keep motion_now_ + run_.left.
    if (run_.left < kNever - 1 - motion_now_) until = motion_now_ + run_.left + 1;
    if (axis_) until = std::min(until, axis_event_at_);
  } else if (axis_) {
    until = axis_->next_time_event();
  }
  return until;
}

void Chip::latched_changed() {
  latched_bits_ = encode_latched(layout_, latched_);
  latches_dirty();
}



void Chip::clear_latches() {
  if (!(latched_ == condition_)) {
    latched_ = condition_;
    latched_changed();
  }
  latched_clean_ = true;
  // GetStatus also lets the bridges be enabled again once the overcurrent is gone.
  if (!condition_.ocd) ocd_shutdown_ = false;
}

void Chip::wrong_command(std::uint8_t byte, const char* why, DiagnosticDetail detail) {
  latched_.wrong_cmd = true;
  latched_changed();
  if (sink_) sink_({now_, DiagnosticKind::wrong_cmd, "byte " + hex(byte, 2) + ": " + why, detail});
}

void Chip::not_performable(const char* what, DiagnosticDetail detail) {
  latched_.notperf_cmd = true;
  latched_changed();
  if (sink_) sink_({now_, DiagnosticKind::notperf_cmd, what, detail});
}

// ---------------------------------------------------------------- time

void Chip::sync() const {
  if (motion_now_ >= now_) return;
  if (axis_) {
    // Axis events change the chip's inputs (SW, stall, overcurrent): not a const affair, but
    // a Chip is never const-constructed where an axis can be attached.
    const_cast<Chip*>(this)->sync_with_axis();
    return;
  }
  Tick left = now_ - motion_now_;
  motion_now_ = now_;
  if (!motion_active(motion_)) return;
  if (engine_ == MotionEngine::reference) {
    forget_live_bits();
    reference_advance(motion_, profile_, left);
    return;
  }
  if (fast_advance(motion_, profile_, left, run_)) forget_live_bits();
}

Tick Chip::next_event_tick() const {
  if (motion_active(motion())) return now_ + 1;
  return axis_ ? axis_->next_time_event() : kNever;
}

// ---------------------------------------------------------------- pins

bool Chip::busy_sync_pin() const {
  sync();
  return busy_level();
}

Chip::OutputLevels Chip::output_levels() const {
  OutputLevels o;
  const bool plain = stby_level_ && !axis_ && !sync_clock_on();
  if (plain && now_ < status_until_ && layout_.busy >= 0) {
    // Inside the run of uniform ticks the cached STATUS is good for: BUSY is its bit and the
    // motion neither starts nor ends, so nothing needs working out.
    o.busy = ((status_word_ >> layout_.busy) & 1u) != 0;
    o.flag = flag_level();
    o.sw = sw_level_;
    o.active = motion_active(motion_);
    o.steady_through = status_until_ - 1;
    return o;
  }
  sync();  // once: what follows reads the state as of now
  o.busy = busy_level();
  o.flag = flag_level();
  o.sw = sw_level_;
  o.active = motion_active(motion_) || (axis_ && axis_->next_time_event() != kNever);
  o.steady_through = now_;
  // Without an axis or a SYNC clock the levels change on their own only where the motion
  // leaves its run of uniform ticks (the premise of the STATUS cache: MOT_STATUS and BUSY are
  // constant inside one), and a latched flag only by something done to the chip.
  if (plain) {
    if (!o.active)
      o.steady_through = kNever;
    else if (run_.known && now_ - motion_now_ <= run_.left && run_.left < kNever - motion_now_)
      o.steady_through = motion_now_ + run_.left;
  } else if (!stby_level_) {
    o.steady_through = kNever;  // held in standby: BUSY high, nothing moves
  }
  return o;
}

bool Chip::sync_clock_on() const { return variant_->pins.busy_sync && (reg(Reg::STEP_MODE) & kStepModeSyncEn) != 0; }

bool Chip::busy_level() const {
  if (!stby_level_ || !variant_->pins.busy_sync) return true;  // no pin: nothing pulls it low
  if (sync_clock_on()) {
    const unsigned sync_sel = (reg(Reg::STEP_MODE) >> 4) & 7u;
    return ((motion_.el_pos >> (7 - sync_sel)) & 1u) != 0;
  }
  return !motion_busy(motion_, profile_);
}

bool Chip::flag_level() const {
  const AlarmFlags& a = latched_;
  // Nothing latched (the usual case): released, whatever ALARM_EN enables.
  if (!(a.uvlo | a.uvlo_adc | a.ocd | a.stall_a | a.stall_b | a.wrong_cmd | a.notperf_cmd | a.sw_evn) &&
      a.thermal == Thermal::normal)
    return true;
  const std::uint32_t enabled = reg(Reg::ALARM_EN);
  for (unsigned bit = 0; bit < 8; ++bit) {
    if (((enabled >> bit) & 1u) == 0) continue;
    bool on = false;
    switch (variant_->alarms[bit]) {
      case Alarm::none: break;
      case Alarm::overcurrent: on = a.ocd; break;
      case Alarm::thermal_shutdown: on = a.thermal >= Thermal::bridge_shutdown; break;
      case Alarm::thermal_warning: on = a.thermal >= Thermal::warning; break;
      case Alarm::uvlo: on = a.uvlo; break;
      case Alarm::adc_uvlo: on = a.uvlo_adc; break;
      case Alarm::stall_a: on = a.stall_a; break;
      case Alarm::stall_b: on = a.stall_b; break;
      case Alarm::stall_any: on = a.stall_a || a.stall_b; break;
      case Alarm::switch_turn_on: on = a.sw_evn; break;
      case Alarm::command_error: on = a.wrong_cmd || a.notperf_cmd; break;
    }
    if (on) return false;
  }
  return true;
}

bool Chip::flag_pin() const {
  if (axis_) sync();  // a mechanical event may have latched a flag since
  return flag_level();
}

void Chip::set_sw_pin(bool level) {
  sync();
  drive_sw(level);
}

void Chip::drive_sw(bool level) {
  touched();
  if (level == sw_level_ || !variant_->pins.sw) return;  // no SW input: nothing to drive
  sw_level_ = level;
  if (!stby_level_) return;
  if (!level)
    switch_turn_on_event();
  else
    switch_release_event();
}

void Chip::switch_turn_on_event() {
  latched_.sw_evn = true;
  latched_changed();
  const bool sw_mode = (reg(Reg::CONFIG) & kConfigSwMode) != 0;
  if (motion_.activity == Activity::go_until) {
    if (switch_act_)
      reg(Reg::MARK) = static_cast<std::uint32_t>(motion_.abs_pos) & kPosMask;
    else
      motion_.abs_pos = 0;
    if (sw_mode)
      soft_stop(motion_, profile_, false);
    else
      hard_stop(motion_);
    return;
  }
  // SW_MODE = 0: every turn-on event is a HardStop interrupt, bridges included.
  if (!sw_mode && !hiz_forced()) hard_stop(motion_);
}

void Chip::switch_release_event() {
  if (motion_.activity != Activity::release_sw) return;
  if (switch_act_)
    reg(Reg::MARK) = static_cast<std::uint32_t>(motion_.abs_pos) & kPosMask;
  else
    motion_.abs_pos = 0;
  hard_stop(motion_);
}

void Chip::set_stck_pin(bool level) {
  sync();
  touched();
  const bool rising = level && !stck_level_;
  stck_level_ = level;
  // Without a motion engine (the L6474) an edge moves the motor only with the bridges enabled.
  if (rising && stby_level_ && motion_.activity == Activity::step_clock && (variant_->motion_engine || !motion_.hiz))
    take_microstep(motion_, profile_);
  if (axis_) axis_after_change();
}

void Chip::stck_pulses(std::uint64_t n) {
  if (axis_) {  // the axis has its rules at every step: one pulse after the other
    set_stck_pin(false);
    for (std::uint64_t i = 0; i < n; ++i) {
      set_stck_pin(true);
      set_stck_pin(false);
    }
    return;
  }
  sync();
  touched();
  stck_level_ = false;
  // Nothing a microstep changes decides whether the next edge steps: the condition holds for all n.
  if (n && stby_level_ && motion_.activity == Activity::step_clock && (variant_->motion_engine || !motion_.hiz))
    take_microsteps(motion_, profile_, n);
}

void Chip::set_dir_pin(bool level) {
  sync();
  touched();
  dir_level_ = level;
  if (variant_->pins.dir) motion_.dir = level;
}

void Chip::set_stby_rst_pin(bool level) {
  sync();
  touched();
  if (level == stby_level_) return;
  stby_level_ = level;
  reset_logic();
  if (level) come_out_of_reset();
  if (axis_) axis_after_change();
}

void Chip::set_adc_input(std::uint8_t code) { adc_code_ = std::min<std::uint8_t>(code, 31); }

// ---------------------------------------------------------------- faults

bool Chip::hiz_forced() const {
  return condition_.uvlo || condition_.thermal >= Thermal::bridge_shutdown || ocd_shutdown_;
}

void Chip::apply_forced_hiz() {
  if (hiz_forced()) hard_hiz(motion_);
}

void Chip::set_undervoltage(bool active) {
  sync();
  touched();
  condition_.uvlo = active;
  latches_dirty();
  if (!stby_level_) return;
  if (active) latched_.uvlo = true;
  latched_changed();
  apply_forced_hiz();
  if (axis_) axis_after_change();
}

void Chip::set_adc_undervoltage(bool active) {
  condition_.uvlo_adc = active;
  latches_dirty();
  if (stby_level_ && active) latched_.uvlo_adc = true;
  latched_changed();
}

void Chip::set_thermal(Thermal t) {
  sync();
  touched();
  // Shutdown has hysteresis: it only ends once the die is back below the warning level.
  if (condition_.thermal >= Thermal::bridge_shutdown && t == Thermal::warning) t = condition_.thermal;
  condition_.thermal = t;
  latches_dirty();
  if (!stby_level_) return;
  latched_.thermal = std::max(latched_.thermal, t);
  latched_changed();
  apply_forced_hiz();
  if (axis_) axis_after_change();
}

void Chip::set_overcurrent(bool active) {
  sync();
  touched();
  condition_.ocd = active;
  latches_dirty();
  if (!stby_level_ || !active) return;
  latched_.ocd = true;
  latched_changed();
  if ((reg(Reg::CONFIG) & kConfigOcSd) != 0) ocd_shutdown_ = true;
  apply_forced_hiz();
}

void Chip::power_cycle() {
  sync();
  touched();
  reset_logic();  // the shaft's travel is kept: the rotor does not move with the power
  if (stby_level_) come_out_of_reset();
  if (axis_) axis_after_change();
}

void Chip::set_stall(Bridge bridge, bool active) {
  (bridge == Bridge::A ? condition_.stall_a : condition_.stall_b) = active;
  latches_dirty();
  if (!stby_level_ || !active) return;
  (bridge == Bridge::A ? latched_.stall_a : latched_.stall_b) = true;
  latched_changed();
}

// ---------------------------------------------------------------- inspection

std::uint32_t Chip::peek(Reg id) const {
  sync();
  const RegisterInfo* r = table_->find(id);
  return r ? register_value(*r) : 0;
}

std::uint32_t Chip::peek_address(std::uint8_t address) const {
  sync();
  const RegisterInfo* r = table_->at_address(address);
  return r ? register_value(*r) : 0;
}

std::string Chip::dump() const {
  sync();
  std::string out;
  out += std::string(variant_->name) + " at tick " + std::to_string(now_) + (stby_level_ ? "" : " (in standby)") + "\n";
  for (const auto& r : table_->registers) {
    const std::uint32_t v = register_value(r);
    char line[96];
    std::snprintf(line, sizeof line, "  0x%02X %-10s = 0x%0*X", r.address, std::string(r.name).c_str(),
                  r.spi_bytes() * 2, v);
    out += line;
    if (r.is_signed()) out += "  (" + std::to_string(sign_extend(v, r.bits)) + ")";
    if (r.id == Reg::STATUS) out += "  [" + describe_status(layout_, static_cast<std::uint16_t>(v)) + "]";
    out += '\n';
  }
  return out;
}

// ---------------------------------------------------------------- the mechanical axis

namespace {
// Longest stretch searched for an axis event at once (about 4.8 h of chip time): keeps the
// closed-form positions far from overflow; a longer quiet run is searched again after it.
constexpr Tick kAxisHorizon = Tick{1} << 36;
}  // namespace

void Chip::attach_axis(const AxisSpec& spec) {
  sync();
  touched();
  axis_ = ValuePtr<Axis>(std::make_unique<Axis>(spec, motion_.travel));
  drive_stale_ = true;
  axis_sw_ = sw_level_;
  axis_stall_ = false;
  axis_ocd_ = false;
  forget_axis_event();
  axis_after_change();
}

void Chip::detach_axis() {
  sync();
  touched();
  axis_.reset();
}

const Axis* Chip::axis() const {
  if (!axis_) return nullptr;
  sync();
  axis_->observe(motion_, profile_);
  return axis_.get();
}

void Chip::set_axis_load(const LoadSpec& load) {
  if (!axis_) return;
  sync();
  touched();
  axis_->set_load(load);
  forget_axis_event();
  axis_settle(now_);
}

void Chip::set_axis_stops(bool has_lower, std::int64_t lower, bool has_upper, std::int64_t upper) {
  if (!axis_) return;
  sync();
  touched();
  axis_->set_stops(has_lower, lower, has_upper, upper);
  axis_event_known_ = false;
  axis_settle(now_);
}

void Chip::set_axis_supply(std::uint32_t supply_mV) {
  if (!axis_) return;
  sync();
  touched();
  axis_->set_supply(supply_mV);
  axis_event_known_ = false;
  axis_settle(now_);
}

DriveInputs Chip::drive_inputs() const {
  auto value = [&](Reg id) -> std::uint32_t {
    const RegisterInfo* r = table_->find(id);
    return r ? regs_[r->address] & r->mask() : 0;
  };
  const bool gate_driver = variant_->has(Reg::GATECFG1);
  DriveInputs d;
  if (table_->has(Reg::TVAL)) {
    // One torque value whatever the motor does (the L6474). EN_TQREG's ADC_OUT is not modelled.
    d.mode = DriveMode::current_ma;
    const auto tval = static_cast<std::uint8_t>(value(Reg::TVAL));
    d.level = {tval, tval, tval, tval};
  } else if (table_->has(Reg::TVAL_RUN)) {
    d.mode = gate_driver ? DriveMode::current_sense : DriveMode::current_ma;
    d.level = {static_cast<std::uint8_t>(value(Reg::TVAL_HOLD)), static_cast<std::uint8_t>(value(Reg::TVAL_RUN)),
               static_cast<std::uint8_t>(value(Reg::TVAL_ACC)), static_cast<std::uint8_t>(value(Reg::TVAL_DEC))};
  } else {
    d.mode = DriveMode::voltage;
    d.level = {static_cast<std::uint8_t>(value(Reg::KVAL_HOLD)), static_cast<std::uint8_t>(value(Reg::KVAL_RUN)),
               static_cast<std::uint8_t>(value(Reg::KVAL_ACC)), static_cast<std::uint8_t>(value(Reg::KVAL_DEC))};
    d.st_slp = static_cast<std::uint8_t>(value(Reg::ST_SLP));
    d.fn_slp_acc = static_cast<std::uint8_t>(value(Reg::FN_SLP_ACC));
    d.fn_slp_dec = static_cast<std::uint8_t>(value(Reg::FN_SLP_DEC));
    d.int_speed = static_cast<std::uint16_t>(value(Reg::INT_SPEED));
    d.k_therm = static_cast<std::uint8_t>(value(Reg::K_THERM));
  }
  if (table_->has(Reg::STALL_TH)) {
    d.stall_kind = gate_driver ? Comparator::vds_31mV : Comparator::current_31mA;
    d.stall_th = static_cast<std::uint8_t>(value(Reg::STALL_TH));
  }
  if (table_->has(Reg::OCD_TH)) {
    d.ocd_kind = gate_driver ? Comparator::vds_31mV : Comparator::current_375mA;
    d.ocd_th = static_cast<std::uint8_t>(value(Reg::OCD_TH));
  }
  d.acc = profile_.acc;
  d.dec = profile_.dec;
  d.infinite = profile_.infinite;
  return d;
}

void Chip::axis_after_change() {
  if (drive_stale_) {
    axis_->set_drive(drive_inputs());
    drive_stale_ = false;
  }
  forget_axis_event();
  axis_settle(now_);
}

void Chip::axis_settle(Tick at) {
  // The axis's outputs are the chip's SW pin, stall and overcurrent inputs; a change of them can
  // change the motion (a switch stops a GoUntil, OC_SD disables the bridges), so settle again.
  for (int round = 0; round < 8; ++round) {
    if (axis_->settle(motion_, profile_, at)) forget_axis_event();
    bool drove = false;
    if (axis_->sw_level() != axis_sw_) {
      axis_sw_ = axis_->sw_level();
      if (axis_sw_ != sw_level_) {
        drive_sw(axis_sw_);
        drove = true;
      }
    }
    if (axis_->stall_condition() != axis_stall_) {
      axis_stall_ = axis_->stall_condition();
      set_stall(Bridge::A, axis_stall_);
      set_stall(Bridge::B, axis_stall_);
      touched();
      drove = true;
    }
    if (axis_->overcurrent_condition() != axis_ocd_) {
      axis_ocd_ = axis_->overcurrent_condition();
      set_overcurrent(axis_ocd_);
      drove = true;
    }
    if (!drove) return;
    forget_axis_event();
  }
}

bool Chip::axis_quiet_through_now() const {
  if (motion_active(motion_)) return run_.known && axis_event_known_ && now_ < axis_event_at_;
  return axis_->next_time_event() > now_;
}

void Chip::sync_with_axis() {
  Tick t = motion_now_;
  Tick left = now_ - t;
  motion_now_ = now_;
  while (left > 0) {
    if (!motion_active(motion_)) {
      // Standing still: only switch bounce edges happen on their own.
      const Tick e = std::max(axis_->next_time_event(), t + 1);
      if (e == kNever || e > t + left) break;
      left -= e - t;
      t = e;
      forget_live_bits();
      axis_settle(t);
      continue;
    }
    if (engine_ == MotionEngine::reference) {
      reference_tick(motion_, profile_);
      ++t;
      --left;
      forget_live_bits();
      axis_settle(t);
      continue;
    }
    if (!run_.known) {
      run_.left = uniform_ticks(motion_, profile_, kNever - 1);
      run_.known = true;
      forget_axis_event();
    }
    if (!axis_event_known_) {
      axis_event_at_ = t + axis_->first_event(motion_, profile_, std::min(run_.left, kAxisHorizon), t);
      axis_event_known_ = true;
    }
    const Tick to_event = axis_event_at_ - t;
    const Tick n = std::min(run_.left, left);
    if (to_event <= n) {
      apply_uniform_ticks(motion_, profile_, to_event);
      run_.left -= to_event;
      left -= to_event;
      t += to_event;
      forget_live_bits();
      forget_axis_event();
      axis_settle(t);
      continue;
    }
    apply_uniform_ticks(motion_, profile_, n);
    run_.left -= n;
    left -= n;
    t += n;
    if (left == 0) break;
    reference_tick(motion_, profile_);
    --left;
    ++t;
    run_.known = false;
    forget_live_bits();
    axis_settle(t);
  }
}

}  // namespace l6470emu
