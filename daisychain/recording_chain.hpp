// A chain that records itself: every CS frame (with its times, MOSI and MISO), every
// backdoor pin or fault change, and the BUSY/FLAG levels it sees change, go to a
// TraceSink (a native trace file is flushed event by event). Any transport — in-process
// tests, spidev messages, the preload or daemon — records by talking to this instead of
// the Chain. It adds no behaviour of its own and is not thread-safe.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "daisychain/chain.hpp"
#include "spi/spi_device.hpp"
#include "spi/trace.hpp"

namespace l6470emu {

/// Choices for a recording.
struct RecordOptions {
  /// Record every chip's BUSY and FLAG changes: after each frame and event, and at their own
  /// ticks as time passes (replay then checks them). Costs a motion update per chip per frame.
  bool observe_outputs = true;
  /// The board description of the chain (board/board_config.hpp's text: variants, axes,
  /// numbering, quirks, checks), written as the header's `board` lines so that a replay builds
  /// the same world. Empty: only the `chain` line (the variants).
  std::string board;
};

/// Records what happens to a Chain through it.
class RecordingChain final : public SpiDevice {
 public:
  /// Records `chain` into `sink` (the header, with the chain's description, is written now,
  /// followed by the chips' BUSY and FLAG levels). Both must outlive the recorder.
  RecordingChain(Chain& chain, TraceSink& sink, RecordOptions options = {});

  // SpiDevice: forwarded to the chain; a frame is recorded at its CS rising edge.
  void select() override;
  std::uint8_t exchange(std::uint8_t mosi) override;
  void exchange(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) override;
  void deselect() override;
  bool selected() const override { return chain_.selected(); }
  // The bit-level face: frames record the bytes as the host sent and read them, and the host's
  // wire settings (TraceEvent::wire: mode, bit order, word size and speed of the frame's first
  // exchange_wire, and whether its CS edges were timed: select_wire() rather than select()).
  void select_wire() override;
  void exchange_wire(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx, const WireSettings& wire) override;
  void deselect_wire() override;
  Tick now() const override { return chain_.now(); }
  /// Lets time pass. With CS high, every change of a chip's BUSY or FLAG on the way is
  /// recorded at its own tick (a BUSY that is the SYNC clock only when looked at); with CS low,
  /// changes are recorded when CS rises.
  void advance_to(Tick tick) override;

  // The physical world, recorded (chip k of the chain). Changes made while CS is low are
  // written after the frame's line (a trace line's time never goes back).
  void set_sw_pin(std::size_t chip, bool level);
  void set_stck_pin(std::size_t chip, bool level);
  void set_dir_pin(std::size_t chip, bool level);
  void set_stby_rst_pin(std::size_t chip, bool level);
  void set_adc_input(std::size_t chip, std::uint8_t code);
  void set_undervoltage(std::size_t chip, bool active);
  void set_adc_undervoltage(std::size_t chip, bool active);
  void set_thermal(std::size_t chip, Thermal t);
  void set_overcurrent(std::size_t chip, bool active);
  void set_stall(std::size_t chip, Bridge bridge, bool active);
  /// Chip `chip` loses power and is back at once (Chain::power_cycle); recorded as
  /// `fault K POWER_CYCLE`. With CS low it happens, and is written, after the frame.
  void power_cycle(std::size_t chip);
  /// The next frame's MISO byte at chip `chip`'s position has bit `bit` inverted
  /// (Chain::arm_miso_flip); recorded as `fault K MISO_FLIP BIT`.
  void miso_flip(std::size_t chip, std::uint8_t bit);
  /// Chip `chip` misses the next frame (Chain::arm_lost_frame); recorded as `fault K LOST_FRAME`.
  void lost_frame(std::size_t chip);
  /// The load on chip `chip`'s axis changes (no effect on the chip without an axis, but recorded).
  void set_axis_load(std::size_t chip, const LoadSpec& load);
  /// An axis is attached to chip `chip` (replacing one it had), recorded as an `axis` event
  /// with the whole spec.
  void attach_axis(std::size_t chip, const AxisSpec& spec);
  /// Chip `chip`'s axis is removed (recorded as `axis K none`).
  void detach_axis(std::size_t chip);
  /// The hard stops of chip `chip`'s axis change (a scenario's `block:`).
  void set_axis_stops(std::size_t chip, bool has_lower, std::int64_t lower, bool has_upper, std::int64_t upper);
  /// The motor supply chip `chip`'s axis sees changes (its torque and current follow).
  void set_axis_supply(std::size_t chip, std::uint32_t supply_mV);
  /// Records that time was moved on to now() with nothing else happening (`ctl advance`), so
  /// that a replay lets the chips run as far.
  void mark_advance();

  /// Records BUSY/FLAG levels, and the SW level of chips with an axis, that changed since they
  /// were last seen (done after every frame and event; call it to catch a change between
  /// frames, e.g. a move ending). Looking again with nothing done to the chain through the
  /// recorder in between is free at the same tick, and at any later one up to where the last
  /// look found every level sure to stay (forever when no chip had anything to do on its own).
  void observe_outputs() {
    if (!options_.observe_outputs || chain_.selected()) return;
    if (observed_at_ != kNever && (idle_ || chain_.now() <= quiet_until_)) return;
    look_at_outputs();
  }
  /// The chain was changed behind the recorder's back (through chain()): the next
  /// observe_outputs() looks even at the same tick.
  void outputs_may_have_changed() {
    observed_at_ = kNever;
    quiet_until_ = 0;
    idle_ = false;
  }

  Chain& chain() { return chain_; }
  std::uint64_t frames_recorded() const { return frames_; }

 private:
  void start_frame(bool timed);
  void finish_frame();
  void look_at_outputs();
  void keep(std::span<const std::uint8_t> tx, std::span<const std::uint8_t> rx);
  void keep_long(std::span<const std::uint8_t> tx, std::span<const std::uint8_t> rx);
  void advance_observing(Tick tick);
  void backdoor(std::size_t chip, TraceEventKind kind, std::uint8_t what, std::uint8_t value);
  Tick first_output_change(std::size_t chip, Tick to, bool& unsure) const;
  void stimulus(const TraceEvent& e);
  void emit(const TraceEvent& e);

  Chain& chain_;
  TraceSink& sink_;
  RecordOptions options_;
  Tick frame_start_ = 0;
  std::vector<std::uint8_t> tx_, rx_;  // the frame's bytes so far: the first frame_bytes_ of them
  std::size_t frame_bytes_ = 0;
  TraceEvent frame_event_;  // the frame written at CS rising, kept (building one per frame cost more than the rest)
  // How the host drives the wire: the last frame's settings, kept for a frame that clocks no byte.
  TraceWire wire_;
  bool frame_timed_ = false;  // this frame's CS fell through select_wire() (t_disCS applies)
  bool wire_noted_ = false;   // this frame's first exchange set wire_
  void note_wire(const TraceWire& wire) {
    if (wire_noted_) return;
    wire_noted_ = true;
    wire_ = wire;  // (a store costs less than comparing first)
  }
  std::uint64_t decoded_at_select_ = 0;  // chain_.decoded_bytes() when CS fell
  std::vector<TraceEvent> deferred_;  // backdoor events while CS is low
  void touched() {
    observed_at_ = kNever;
    idle_ = false;
    quiet_until_ = 0;
  }
  void axis_event(std::size_t chip, TraceEvent& e);

  std::vector<std::uint8_t> busy_, flag_, sw_;
  Tick observed_at_ = kNever;  // tick of the last look at the outputs; kNever after any change
  bool idle_ = false;          // at that look no chip had anything to do on its own
  // No output changes by itself up to here (until the chain is touched): the last look's
  // levels hold. Set by a look (the chips' steady_through) and by advance_to's look ahead.
  Tick quiet_until_ = 0;
  std::uint64_t frames_ = 0;
};

}  // namespace l6470emu
