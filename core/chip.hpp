// One dSPIN-family chip: register file, command decoder, STATUS, pins and the
// motion engine, advanced on a virtual 250 ns clock. The SPI face is byte-level
// (one call per byte decoded at a CS rising edge); bus framing lives in spi/ and daisychain/.
#pragma once

#include <array>
#include <cassert>
#include <cstdint>
#include <string>

#include "core/axis.hpp"
#include "core/commands.hpp"
#include "core/diagnostics.hpp"
#include "core/fast_motion.hpp"
#include "core/motion.hpp"
#include "core/quirks.hpp"
#include "core/registers.hpp"
#include "core/status.hpp"
#include "core/tick.hpp"
#include "core/value_ptr.hpp"
#include "core/variant.hpp"

namespace l6470emu {

/// Which power bridge a stall was detected on.
enum class Bridge : std::uint8_t { A, B };

/// A chip of the family, from power-up on. Copying a chip copies its whole state.
/// Aligned to a cache line, so that the fields a SPI byte touches share one.
class alignas(64) Chip {
 public:
  /// A chip just out of power-up: registers at reset, bridges HiZ, UVLO latched, FLAG low.
  explicit Chip(const Variant& variant = l6470(), Quirks quirks = {});

  /// Which family member this is.
  const Variant& variant() const { return *variant_; }
  /// The register table in force: the variant's, or on a powerSTEP01 with STEP_MODE.CM_VM = 1
  /// its current-mode reading (TVAL_* and so on at 0x09-0x10).
  const Variant& registers() const { return *table_; }
  /// The STATUS layout in force (the variant's, with the stall-bit quirk applied).
  const StatusLayout& status_layout() const { return layout_; }
  const Quirks& quirks() const { return quirks_; }

  // ---- SPI face -----------------------------------------------------------

  /// The byte in the chip's shift register at a CS rising edge: decode it and
  /// return the byte the chip loads for the next transfer (0x00 with no response
  /// pending). In standby the byte is ignored and 0x00 is returned.
  std::uint8_t on_byte(std::uint8_t byte) {
    if (byte == 0x00 && ready_for_command_) return next_response_byte();  // NOP
    return decode_byte(byte);
  }

  /// on_byte() for a byte decoded at tick `now` >= now() (a chain's CS rising edge): the chip
  /// is first brought to `now` unless the byte is a NOP outside a command, which only clocks an
  /// answer on and needs no up-to-date state. Equal to advance_to(now) then on_byte(byte).
  std::uint8_t on_byte_at(Tick now, std::uint8_t byte) {
    if (ready_for_command_) {
      if (byte == 0x00) return next_response_byte();  // NOP
      assert(now >= now_);
      now_ = now;
      // GetStatus, the polling command, while its answer is known without working the motion out.
      if (byte == 0xD0 && now < status_until_ && !has_command_sink_) {
        const std::uint16_t status = cached_status();  // nothing latched to clear: a plain read
        response_ = status & 0xFFu;
        response_left_ = 1;
        return static_cast<std::uint8_t>(status >> 8);
      }
      return decode_byte(byte);
    }
    advance_to(now);
    return decode_byte(byte);
  }

  /// on_byte_at(now, 0x00), a NOP, that also ORs into `noise` something nonzero unless the chip
  /// is left quiet: ready for an opcode with no answer byte left, so that further NOPs change
  /// nothing and shift out 0x00 until some other byte, a pin or a fault reaches it.
  std::uint8_t on_nop_at(Tick now, std::uint32_t& noise) {
    if (ready_for_command_) {
      const std::uint8_t out = next_response_byte();
      noise |= response_ | response_left_;
      return out;
    }
    noise |= 1;
    return on_byte_at(now, 0x00);
  }

  /// Whether the decoder is in the middle of a command (collecting argument bytes).
  bool collecting_arguments() const { return collecting_; }
  /// While collecting_arguments(): the command being collected (its opcode's decoding), how many
  /// argument bytes it still needs and the ones it has, MSB first (for the sanitizer, board/).
  Command collecting_command() const { return collecting_ ? pending_.command : Command::NOP; }
  const Opcode& collecting_opcode() const { return pending_; }
  std::uint8_t arguments_missing() const { return collecting_ ? static_cast<std::uint8_t>(pending_.arg_bytes - args_seen_) : 0; }
  std::uint32_t arguments_so_far() const { return collecting_ ? arg_ : 0; }
  /// Bytes of the GetParam/GetStatus answer not yet loaded into the shift register (a new
  /// GetParam or GetStatus drops them).
  std::uint8_t answer_bytes_pending() const { return response_left_; }

  /// Whether the chip takes part in SPI (false while STBY/RST is held low).
  bool spi_enabled() const { return stby_level_; }

  // ---- time ---------------------------------------------------------------

  /// The chip's current virtual time.
  Tick now() const { return now_; }
  /// Runs the chip up to `tick` (never backwards; an earlier tick is ignored). The motion
  /// itself is worked out lazily, when something looks at it or a command needs it.
  void advance_to(Tick tick) {
    if (tick > now_) now_ = tick;
  }
  /// The next tick at which the chip changes on its own (kNever when idle).
  Tick next_event_tick() const;
  /// Chooses the motion engine: the event-driven one (default) or the tick-by-tick reference.
  void set_motion_engine(MotionEngine e) {
    engine_ = e;
    touched();  // the engines remember different things
  }
  MotionEngine motion_engine() const { return engine_; }

  // ---- pins (the physical world; host programs only see SPI and these) ------

  /// BUSY\SYNC output level: false = pulled low (busy, or the SYNC clock low). Always high on
  /// a part without the pin (the L6474).
  bool busy_sync_pin() const;
  /// Whether BUSY\SYNC outputs the SYNC clock (STEP_MODE.SYNC_EN on a part with the pin).
  bool sync_clock_on() const;
  /// FLAG output level: false = pulled low (an enabled alarm is active).
  bool flag_pin() const;
  /// SW input level; false = switch closed (pin pulled to ground). Edges act at now(). A part
  /// without a SW input (the L6474) ignores it.
  void set_sw_pin(bool level);
  bool sw_pin() const {
    if (axis_) sync();  // the axis's switches drive it
    return sw_level_;
  }
  /// STCK input level; a rising edge in step-clock mode makes one microstep (on a part without
  /// a motion engine, the L6474: each rising edge while the bridges are enabled).
  void set_stck_pin(bool level);
  /// `n` whole STCK pulses at now(), ending low: exactly set_stck_pin(true) then
  /// set_stck_pin(false), `n` times (a pin left high is first taken low, which moves nothing).
  /// Without an axis the cost does not grow with `n`; with one each pulse is applied in turn,
  /// so that the axis sees every step.
  void stck_pulses(std::uint64_t n);
  /// DIR input level (the L6474's; the other parts have no such pin and ignore it): the
  /// direction STCK steps in, high = forward. STATUS DIR shows it.
  void set_dir_pin(bool level);
  bool dir_pin() const { return dir_level_; }
  /// STBY\RST input; low holds the logic in reset with SPI silent, rising edge = power-up state.
  void set_stby_rst_pin(bool level);
  /// The ADC_OUT conversion of the ADCIN pin, 0..31 (larger values saturate).
  void set_adc_input(std::uint8_t code);

  // ---- faults ---------------------------------------------------------------

  /// Motor supply below VSthOff (true) or back above VSthOn (false).
  void set_undervoltage(bool active);
  /// ADC input undervoltage (UVLO_ADC, gate-driver parts).
  void set_adc_undervoltage(bool active);
  /// Die temperature class of the physical die. The chip applies the hysteresis itself: a
  /// shutdown only ends when the die is back to `normal` (below the warning threshold).
  void set_thermal(Thermal t);
  /// Overcurrent in a power MOSFET; with CONFIG.OC_SD the bridges shut down.
  void set_overcurrent(bool active);
  /// Stall (step loss) detected on a bridge.
  void set_stall(Bridge bridge, bool active);
  /// A brown-out: the chip loses its supply and gets it back at once. It comes back as a new
  /// chip does (registers at reset, ABS_POS 0, bridges HiZ, UVLO latched, FLAG low), dropping
  /// any command being collected and any answer; its pins, the physical conditions (thermal,
  /// overcurrent...) and its axis, whose rotor stays where it is with the bridges off, remain.
  /// With STBY\RST held low the logic stays in reset. The shift register is the chain's
  /// (Chain::power_cycle empties it).
  void power_cycle();

  // ---- the mechanical world (optional) ----------------------------------------

  /// Puts a motor, its load, hard stops and switches behind the chip (replacing any earlier
  /// axis). From now on the axis drives SW, the stall and the overcurrent conditions; the rotor
  /// starts at `spec.start_position`, synchronised. Without an axis nothing of this exists.
  void attach_axis(const AxisSpec& spec);
  /// Removes the axis; the chip's inputs stay as the axis last left them.
  void detach_axis();
  /// The axis brought up to now() (true position, lost steps, switches), or nullptr.
  const Axis* axis() const;
  /// Whether an axis is attached (without bringing it up to now()).
  bool has_axis() const { return static_cast<bool>(axis_); }

  /// How many bytes have gone through the command decoder. A byte that does not (a NOP while
  /// ready for a command, a GetStatus answered from the cached STATUS) changes nothing but the
  /// answer being shifted out: a recording that sees this count unchanged over a frame knows
  /// the frame changed no pin.
  std::uint64_t decoded_bytes() const { return decoded_bytes_; }

  /// What a recording watches, worked out at once: the BUSY\SYNC, FLAG and SW levels
  /// (busy_sync_pin(), flag_pin(), sw_pin()), whether the chip changes on its own later
  /// (next_event_tick() != kNever), and the last tick through which the three levels are sure
  /// to stay as they are unless something is done to the chip (a byte decoded, a pin, a fault):
  /// the end of the motion's run of uniform ticks, or now() when that is not known.
  struct OutputLevels {
    bool busy = true, flag = true, sw = true, active = false;
    Tick steady_through = 0;
  };
  OutputLevels output_levels() const;
  /// Changes the axis's load at runtime (no effect without an axis).
  void set_axis_load(const LoadSpec& load);
  /// Changes the axis's hard stops at runtime (no effect without an axis): a stop put where the
  /// rotor would pass blocks it there as a built-in one does.
  void set_axis_stops(bool has_lower, std::int64_t lower, bool has_upper, std::int64_t upper);
  /// Changes the motor supply the axis sees (torque and current follow; no effect without an
  /// axis). The UVLO flag is the backdoor's business (set_undervoltage).
  void set_axis_supply(std::uint32_t supply_mV);

  // ---- inspection without side effects --------------------------------------

  /// The value GetParam would return now for `id` (0 when the variant lacks it).
  std::uint32_t peek(Reg id) const;
  /// The value GetParam would return now for `address` (0 for a hole).
  std::uint32_t peek_address(std::uint8_t address) const;
  /// STATUS as GetParam(STATUS) reads it, without clearing anything.
  std::uint16_t status() const {
    if (!stby_level_) return 0;
    if (now_ < status_until_) return cached_status();
    return status_slow();
  }
  /// ABS_POS as a signed number of (micro)steps.
  std::int32_t position() const { return motion().abs_pos; }
  /// The motion engine's state (speed in 2^-40 step/tick and so on).
  const MotionState& motion() const {
    sync();
    return motion_;
  }
  /// The profile the registers currently define.
  const Profile& profile() const { return profile_; }
  /// Whether the bridges are in high impedance.
  bool hiz() const { return motion().hiz; }
  /// Text dump of every register, STATUS decoded.
  std::string dump() const;

  /// Where diagnostics go (unknown opcodes, refused commands).
  void set_diagnostic_sink(DiagnosticSink sink) { sink_ = std::move(sink); }
  /// Who hears of every command the chip decodes (its opcode and argument), before it runs.
  /// Observers only (a scenario's "command seen"): the sink must not call back into the chip.
  using CommandSink = std::function<void(const Opcode& op, std::uint32_t arg)>;
  void set_command_sink(CommandSink sink) {
    command_sink_ = std::move(sink);
    has_command_sink_ = static_cast<bool>(command_sink_);
  }

 private:
  std::uint8_t decode_byte(std::uint8_t byte);
  std::uint8_t next_response_byte() {
    const auto byte = static_cast<std::uint8_t>(response_);
    response_ >>= 8;
    response_left_ -= response_left_ != 0;
    return byte;
  }
  std::uint16_t status_slow() const;
  /// STATUS while now_ < status_until_.
  std::uint16_t cached_status() const {
    assert(status_known_without_sync() && latched_clean_ && status_word_ == (latched_bits_ | live_bits_));
    return status_word_;
  }
  /// GetStatus with STATUS = `status`: the answer is loaded, the latches cleared, the MSB returned.
  std::uint8_t get_status(std::uint16_t status) {
    response_ = status & 0xFFu;  // the LSB comes next
    response_left_ = 1;
    clear_status_on_get_status();
    return static_cast<std::uint8_t>(status >> 8);
  }
  void reset_logic();
  void set_collecting(bool c) {
    collecting_ = c;
    ready_for_command_ = stby_level_ && !c;
  }
  void come_out_of_reset();
  void execute(const Opcode& op, std::uint32_t arg);
  void exec_set_param(std::uint8_t address, std::uint32_t value);
  void write_register(const RegisterInfo& r, std::uint32_t value);
  void load_response(std::uint32_t value, std::uint8_t bytes) {
    response_ = 0;
    response_left_ = bytes;
    for (std::uint8_t i = 0; i < bytes; ++i) response_ |= ((value >> (8 * i)) & 0xFFu) << (8 * (bytes - 1 - i));
  }
  void refresh_profile();
  void clear_status_on_get_status() {
    if (!latched_clean_) clear_latches();
  }
  void clear_latches();
  bool hiz_forced() const;
  void apply_forced_hiz();
  /// The SW level changes to `level` at the chip's current time (the motion already synced).
  void drive_sw(bool level);
  void switch_turn_on_event();
  void switch_release_event();
  void wrong_command(std::uint8_t byte, const char* why, DiagnosticDetail detail = DiagnosticDetail::none);
  void not_performable(const char* what, DiagnosticDetail detail = DiagnosticDetail::none);
  AlarmFlags live_alarms() const;
  LiveStatus live_status() const;
  bool motion_command_allowed(const char* what);
  bool reset_device_refused_when_enabled() const;
  std::uint32_t register_value(const RegisterInfo& r) const;
  std::uint32_t& reg(Reg id) { return regs_[table_->find(id)->address]; }
  std::uint32_t reg(Reg id) const { return regs_[table_->find(id)->address]; }

  // Fields every SPI byte or GetStatus touches come first, in the chip's first cache line.
  Tick now_ = 0;
  // STATUS is status_word_ (= latched_bits_ | live_bits_, with nothing latched to clear) at every
  // now_ < status_until_ (0: not known). Set by status_slow() from status_known_without_sync();
  // anything that could shorten it, or latch a flag, resets it.
  mutable Tick status_until_ = 0;
  mutable std::uint16_t status_word_ = 0;
  std::uint32_t response_ = 0;  // answer bytes still to shift out, the next in the low byte (then 0x00s)
  std::uint8_t response_left_ = 0;  // how many of them are the answer (0x00 bytes included; the sanitizer's)
  bool collecting_ = false;
  bool stby_level_ = true;
  bool ready_for_command_ = true;  // stby_level_ && !collecting_: the next byte is an opcode
  bool has_command_sink_ = false;  // command_sink_ is set: GetStatus goes the way that reports it
  mutable bool live_bits_known_ = false;
  mutable std::uint16_t live_bits_ = 0;
  std::uint16_t latched_bits_ = 0;  // latched_ encoded in the variant's STATUS layout
  bool latched_clean_ = false;      // latched_ == condition_ is known (GetStatus has nothing to clear)
  const Variant* variant_;
  const Variant* table_;  // variant_ or variant_->current_mode
  mutable UniformRun run_;  // fast engine: uniform ticks left from motion_now_
  mutable Tick motion_now_ = 0;
  Quirks quirks_;
  StatusLayout layout_;
  MotionEngine engine_ = MotionEngine::fast;

  // register storage by address (live registers are computed)
  std::array<std::uint32_t, 32> regs_{};

  // decoder: opcode being collected and its argument bytes
  Opcode pending_{};
  std::uint8_t args_seen_ = 0;
  std::uint32_t arg_ = 0;

  // Motion state as of motion_now_ (<= now_); sync() brings it up to now_.
  mutable MotionState motion_{};
  Profile profile_{};
  // The live half of STATUS, valid until the motion leaves its run of uniform ticks
  // (MOT_STATUS, BUSY, DIR, HiZ, SW_F and SCK_MOD cannot change inside one).
  /// Works the motion out up to now_.
  void sync() const;
  /// BUSY\SYNC and FLAG from the state as it stands (the pins' levels once synced).
  bool busy_level() const;
  bool flag_level() const;
  /// Whether STATUS at now_ is known without working the motion out (inside the cached run).
  /// The first tick at which it would stop being so, as the state stands, is status_horizon().
  bool status_known_without_sync() const {
    if (!live_bits_known_ || (axis_ && !axis_quiet_through_now())) return false;
    return !motion_active(motion_) || (run_.known && now_ - motion_now_ <= run_.left);
  }
  /// With an axis: whether no mechanical event can have happened between the last sync and now().
  bool axis_quiet_through_now() const;
  /// Given status_known_without_sync(): the first tick at which it is false as the state stands
  /// (the end of the cached run, the axis's next event); kNever when that never comes.
  Tick status_horizon() const;
  /// The cached live STATUS bits are out of date.
  void forget_live_bits() const {
    live_bits_known_ = false;
    status_until_ = 0;
  }
  /// The axis's next event must be searched again.
  void forget_axis_event() const {
    axis_event_known_ = false;
    status_until_ = 0;
  }
  /// Something outside the passage of time changed the chip: forget the cached run and STATUS.
  void touched() const {
    run_.known = false;
    forget_live_bits();
  }

  void latched_changed();
  /// Something may have latched: the next GetStatus has to look (and the STATUS cache is void).
  void latches_dirty() {
    latched_clean_ = false;
    status_until_ = 0;
  }

  AlarmFlags latched_{};   // what STATUS shows
  AlarmFlags condition_{}; // what is physically going on (events are never conditions)
  bool ocd_shutdown_ = false;  // bridges held off by OCD until GetStatus releases it
  bool switch_act_ = false;    // ACT of the GoUntil/ReleaseSW in progress

  bool sw_level_ = true;
  bool stck_level_ = false;
  bool dir_level_ = false;
  std::uint8_t adc_code_ = 0;

  DiagnosticSink sink_;
  CommandSink command_sink_;

  // The axis, when attached. Its events are found inside the runs of uniform ticks.
  ValuePtr<Axis> axis_;
  mutable Tick axis_event_at_ = 0;       // absolute tick of the axis's next event in the cached run
  mutable bool axis_event_known_ = false;
  bool axis_sw_ = true, axis_stall_ = false, axis_ocd_ = false;  // what the axis last drove
  bool drive_stale_ = true;  // the registers drive_inputs() reads changed since the axis got them
  std::uint64_t decoded_bytes_ = 0;  // bytes through decode_byte (decoded_bytes()), last: the hot fields keep their places
  /// sync() with an axis: the same engines, stopping at every mechanical event.
  void sync_with_axis();
  /// Lets the axis apply its rules at tick `at` and passes its outputs to the chip's inputs.
  void axis_settle(Tick at);
  /// After a command, a pin or a fault: new drive registers, then the rules at now().
  void axis_after_change();
  DriveInputs drive_inputs() const;
};

}  // namespace l6470emu
