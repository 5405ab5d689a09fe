// The OS-free board every front stands on: the chains of a board description on their buses,
// the named pins of every chip with their levels and edges, one clock, the recordings.
// Single-threaded and lock-free; it knows no device node, file descriptor or thread (linux/'s
// DeviceBoard puts spidev and gpiochip semantics and a lock around it; a firmware front, HAL calls).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "board/board_config.hpp"
#include "board/board_time.hpp"
#include "board/chain_bus.hpp"
#include "board/coverage_collector.hpp"
#include "board/sanitizer.hpp"
#include "board/pins.hpp"
#include "board/pulse_train.hpp"
#include "daisychain/chain.hpp"
#include "daisychain/pin_level_bus.hpp"
#include "daisychain/chip_numbering.hpp"
#include "spi/message.hpp"
#include "spi/trace.hpp"
#include "spi/trace_output.hpp"

namespace l6470emu {

/// A level change of a watched pin, at the tick it happened.
class RecordingChain;

struct PinEdge {
  std::size_t chain = 0;  ///< index of the chain in the board description
  std::size_t chip = 0;   ///< chain index of the chip (0 drives MISO)
  Pin pin = Pin::BUSY;
  bool level = false;     ///< the physical level after the edge (true = high)
  Tick tick = 0;          ///< when it changed
};

/// How a controller clocks a bus for one use (a firmware front's SPI settings). Mode 3, MSB
/// first is what the chips expect; other settings reach them as the wire gives them
/// (docs/spi-interface.md) and the sanitizer names them.
struct BusSettings {
  std::uint32_t speed_hz = 5'000'000;  ///< SCK; each byte takes transfer_ticks(1, speed_hz)
  std::uint8_t mode = 3;               ///< SPI mode: CPOL × 2 + CPHA
  bool lsb_first = false;              ///< the bit order on the wire
  std::uint8_t bits_per_word = 8;      ///< the controller's word size (words reach the bus as bytes, in wire order)
};

/// Where the board reports the edges of watched pins (called inside the board's operations).
using EdgeSink = std::function<void(const PinEdge&)>;

/// The emulated hardware of a board description: one daisy chain per chip-select, the buses
/// they share, every chip's pins, the board's time and the trace recordings. Chip arguments are
/// always chain indices (0 drives MISO); numbering() says how users count them. Not thread-safe:
/// its front serialises every call.
///
/// Time: the chains catch up lazily with the clock (time()). Operations that act "now" (those
/// documented so) first bring the chain up to the board's time, reporting on the way every edge
/// of a watched output pin at its own tick; the raw ones (set_input, level, report_changes)
/// work at the chain's own tick, so that a front can compose them into one step.
class Board {
 public:
  /// Builds the chains of `config` (variants, axes, numbering, check=) on a clock read from
  /// `host` (which must outlive the board). The sanitizer's lines (chip diagnostics, broken
  /// rules of the interface) go to `log`, each rule shown ten times per chip and then counted,
  /// with a tally at every power of ten.
  Board(const BoardConfig& config, LineSink log, HostClock& host);
  ~Board();
  Board(const Board&) = delete;
  Board& operator=(const Board&) = delete;

  // ---- chains -----------------------------------------------------------------

  std::size_t chain_count() const { return chains_.size(); }
  /// Number of chips of chain `chain`.
  std::size_t chip_count(std::size_t chain) const;
  /// How diagnostics and users number the chips (the description's numbering=).
  NumberFrom numbering() const { return numbering_; }
  /// The numbering of chain `chain`: its chain indices as users see them.
  ChipNumbering chip_numbering(std::size_t chain) const { return ChipNumbering(numbering_, chip_count(chain)); }
  /// The description of chain `chain`.
  const ChainConfig& chain_config(std::size_t chain) const;
  /// The chain's name: the last part of its path ("spidev0.0").
  const std::string& chain_name(std::size_t chain) const;
  /// "/dev/spidev0.0: 3 chips (L6470,L6470,L6480)".
  std::string chain_summary(std::size_t chain) const;
  /// Index of the chain called `name` (its name "spidev0.0", path "/dev/spidev0.0", "B.C", or
  /// the "gpiochipN" the description gives its pins), or -1.
  int find_chain(const std::string& name) const;
  /// The chain as it stands at its own tick (for reading; nothing is brought up to the clock).
  const Chain& chain(std::size_t chain) const;
  /// Runs `f` on chain `chain` brought up to the clock, then reports the edges it caused. For
  /// looking at the chips: what `f` changes is not recorded (the stimuli have calls of their own
  /// below, which record).
  void with_chain(std::size_t chain, const std::function<void(Chain&)>& f);

  // ---- SPI: a front clocks bytes on a chain between begin_transfer and end_transfer --------

  /// Starts a use of the bus of chain `chain` by a host that drives it with `wire` (SPI mode,
  /// bit order, CS polarity, word size, SCK: what Arduino's SPISettings and STM32 HAL's
  /// CLKPolarity/CLKPhase/FirstBit say) and returns the device to clock on: the chain (or its
  /// recording while it is recorded) as such a host sees it, watched by the sanitizer. The use
  /// starts when the bus is free: at the board's time, or when the use before it on the same
  /// bus ended, if later (its caller may still be waiting for that end); the chain is brought
  /// there. One controller drives a bus: another chain of the bus left selected is deselected
  /// first. Between begin and end the front selects, exchanges (advancing the device's clock by
  /// each byte's bus time, as run_message does) and deselects as its host would; nothing else
  /// may touch the board.
  SpiDevice& begin_transfer(std::size_t chain, const WireSettings& wire = {});
  /// Ends the use begun by begin_transfer: reports the edges of watched pins at the chain's
  /// tick and frees the bus from then. Returns that tick: the use's end, which the front's
  /// host reaches by waiting (advance_to in virtual time).
  Tick end_transfer(std::size_t chain);
  /// begin_transfer(chain, timing.wire), run_message(transfers, timing), end_transfer. Returns the end tick.
  Tick transfer(std::size_t chain, std::span<const SpiTransfer> transfers, const BusTiming& timing = {});

  // ---- the sanitizer ----------------------------------------------------------------

  /// The board's checks (check= and check.allow= of the description; a front may change them).
  Sanitizer& sanitizer() { return sanitizer_; }
  const Sanitizer& sanitizer() const { return sanitizer_; }
  /// Under check=error: the report of the first broken rule since the last call, taken. A front
  /// ends its host's run with it (the preload: exit status kSanitizerExitStatus).
  std::optional<std::string> take_check_failure(FailureEnd end = FailureEnd::run_ends) { return sanitizer_.take_failure(end); }

  // ---- SPI with the chip select on a pin: a firmware front drives CS and clocks bytes itself ----

  /// Drives the chip select of chain `chain` now, as a microcontroller pin does: `selected`
  /// (low) starts a frame, a rise ends it and the chips decode (recorded, edges reported). The
  /// edges are timed: a CS low less than t_disCS after the last rise finds the chips' answers
  /// not loaded, and the sanitizer says so.
  void drive_chip_select(std::size_t chain, bool selected);
  /// Whether chain `chain`'s chip select is low.
  bool chip_selected(std::size_t chain) const;
  /// Clocks `tx` on a bus whose chains are `chains`: every one of them whose chip select is low
  /// receives the bytes; `rx` (as long as `tx`) gets MISO (0x00 when none is selected; several
  /// selected chains drive MISO together, read as the AND of their bytes). The bytes start at
  /// the board's time, or when the bus's last use ended if later, and each takes the bus time of
  /// `settings.speed_hz`. Mode 3, MSB first takes the chains' byte path; any other mode or bit
  /// order is clocked at bit level (Chain::exchange_wire: a mode-0 host reads each chip's stale
  /// SDO latch as the first bit after CS falls, LSB first arrives bit-reversed). The chains'
  /// sanitizer checks the settings, t_setCS and the frames (take_check_failure). Returns the end
  /// tick (the front moves the board's time there).
  Tick clock_bytes(std::span<const std::size_t> chains, std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx,
                   const BusSettings& settings);

  // ---- SPI at the pins (sck_pin=, mosi_pin=, miso_pin=): a front bit-bangs the bus ----------
  // CS goes through drive_chip_select. Edges act at the board's time; the chain hears them as
  // PinLevelBus says (daisychain/pin_level_bus.hpp): each eighth rising CK edge clocks a byte
  // through the chain's bus (recorded, checked, edges reported) in the mode the edges make.

  /// Drives chain `chain`'s CK input now. A frame's first edge sooner than t_setCS after CS fell
  /// is named (CS_SETUP_TIME); edges while CS is high shift nothing (counted: spi_pins()).
  void drive_spi_clock(std::size_t chain, bool level);
  /// Drives chain `chain`'s SDI input (the host's MOSI) now: sampled at the next rising CK edge.
  void drive_spi_data(std::size_t chain, bool level);
  /// The level chain `chain`'s chip 0 drives on SDO (the host's MISO) now; nullopt while CS is
  /// high (SDO floats).
  std::optional<bool> spi_data_out(std::size_t chain) const;
  /// The pin-level state of chain `chain`'s bus (what the edges so far made).
  const PinLevelBus& spi_pins(std::size_t chain) const;
  /// A front saw the pins' rules broken around chain `chain` where only it can see it (clock
  /// edges with no chip select low): SPI_PINS, as `what` says.
  void report_spi_pins(std::size_t chain, std::string what);

  // ---- pins ---------------------------------------------------------------------

  /// Drives input pin `pin` (SW, STCK, STBY_RST) of chip `chip` now, as the physical world
  /// would, and reports the edges it caused. Returns false for an output pin or a bad index.
  bool drive_pin(std::size_t chain, std::size_t chip, Pin pin, bool level);
  /// Physical level of a pin now (BUSY and FLAG: the chip's outputs; inputs: see level()).
  bool pin_level(std::size_t chain, std::size_t chip, Pin pin);
  /// Raw: drives input pin `pin` at the chain's own tick without reporting edges (a front
  /// driving several pins at once calls report_changes after the last). On a chain whose pins
  /// are on lines (the description's gpiochip=), the board keeps each input's level and a drive
  /// to the level it has is no change; without, every drive goes to the chip as it comes.
  /// Returns false for an output pin or a bad index.
  bool set_input(std::size_t chain, std::size_t chip, Pin pin, bool level);
  /// Raw: physical level of a pin at the chain's own tick. An input on lines reads the level it
  /// is driven to (SW high, STBY_RST high, STCK low until driven); without lines, the chip's
  /// own view (SW with the axis's switches, STBY_RST, and STCK as low).
  bool level(std::size_t chain, std::size_t chip, Pin pin) const;
  /// Starts (true) or stops watching a pin: the board then reports each change of its level to
  /// the edge sink, at its tick (BUSY and FLAG changing by themselves are found at their exact
  /// ticks as time passes). A watch starts from the pin's level at the chain's tick, even when
  /// the pin was already watched.
  void watch_pin(std::size_t chain, std::size_t chip, Pin pin, bool watched);
  /// Starts (true) or stops observing a pin for an observer of the world (a scenario): its
  /// edges go to the observer sink at their ticks, independently of watch_pin's (the front's).
  void observe_pin(std::size_t chain, std::size_t chip, Pin pin, bool observed);
  /// Where the edges of observed pins go (an empty function drops them). Called inside the
  /// board's operations: the sink must only take note, never call the board.
  void set_observer_sink(EdgeSink sink) { observer_sink_ = std::move(sink); }
  /// Whether any pin of chain `chain` is watched by the front.
  bool has_watched_pins(std::size_t chain) const;
  /// Raw: records the outputs of a chain being recorded and reports the changes of its watched
  /// pins, at the chain's own tick.
  void report_changes(std::size_t chain);
  /// Where edges of watched pins go (an empty function drops them).
  void set_edge_sink(EdgeSink sink) { edge_sink_ = std::move(sink); }
  /// The host read output `pin` (BUSY or FLAG) of chip `chip` now: a gpio value read, a
  /// digitalRead, an edge event handed to it. Fronts call it for their host's reads only (not for
  /// their own looks), so that a run can say whether the driver looked at the pin after a fault.
  void note_output_read(std::size_t chain, std::size_t chip, Pin pin);
  /// The board's time at the host's last read of output `pin` of chip `chip` (kNever: never read).
  Tick last_output_read(std::size_t chain, std::size_t chip, Pin pin) const;
  /// An edge event of output `pin` (BUSY or FLAG) of chip `chip` was handed to the host (a
  /// gpio line event read, an interrupt run): a read too, and an edge the program waited on.
  void note_output_edge(std::size_t chain, std::size_t chip, Pin pin, bool rising);

  // ---- pulse trains (board_pulses.cpp): a timer's output on an input pin ----------------

  /// Drives input pin `pin` of chip `chip` with `train` (a PWM timer on STCK): the pin follows
  /// the train edge by edge, each edge at its own tick,
  /// until the train's count is spent (the pin stays low) or stop_pulse_train. A train on STCK
  /// costs nothing per pulse while the chain is not recorded and the chip has no axis: the
  /// pulses up to a tick reach the chip at once (Chip::stck_pulses) when the chain is brought
  /// there; a recorded chain, a chip with an axis or with its SYNC clock on BUSY\SYNC, and any
  /// other pin get every edge at its tick (recorded as any input change). Pulses that fall inside an SPI transfer reach the chip at
  /// the transfer's end. A train already on the pin keeps its pulses that rise before
  /// the new train's first and makes no later one (a timer's new period from its update event on); without
  /// one the pin goes low now. False (nothing done) for a bad
  /// index, an output pin, a train that makes no pulse (PulseTrain::valid) or whose first pulse
  /// rises before the board's time.
  bool drive_pulse_train(std::size_t chain, std::size_t chip, Pin pin, const PulseTrain& train);
  /// Ends the train on the pin now: the edges up to now applied, then the pin driven to
  /// `level`. False when no train drives the pin.
  bool stop_pulse_train(std::size_t chain, std::size_t chip, Pin pin, bool level = false);
  /// The rising edges the pin's train has applied up to now (0 without a train).
  std::uint64_t pulse_train_rises(std::size_t chain, std::size_t chip, Pin pin);
  /// How the board's trains reached the chips since it was made: pulses applied in bulk, and
  /// edges applied one at a time (for tests and benchmarks: a long train is not simulated
  /// pulse by pulse).
  struct PulseTrainCounts {
    std::uint64_t bulk_pulses = 0;
    std::uint64_t single_edges = 0;
  };
  PulseTrainCounts pulse_train_counts() const { return train_counts_; }

  // ---- interface coverage -----------------------------------------------------------

  /// Starts collecting interface coverage (docs/coverage.md) on every chain, from now on.
  void enable_coverage();
  bool coverage_enabled() const { return static_cast<bool>(coverage_); }
  /// What the run has met since enable_coverage() (empty data when it is off).
  CoverageData coverage() const;
  /// Who else hears of every command chip `chip` of chain `chain` decodes (a scenario's
  /// "command seen"), besides coverage; an empty function: nobody. An observer only.
  void set_command_observer(std::size_t chain, std::size_t chip, Chip::CommandSink sink);

  // ---- time ---------------------------------------------------------------------

  /// The board's time (the one owner of the clock).
  BoardTime& time() { return time_; }
  const BoardTime& time() const { return time_; }
  /// Brings chain `chain` up to the board's time, reporting the edges on the way.
  void catch_up(std::size_t chain);
  /// Virtual time: moves every chain on by `ticks` (edges reported on the way), as `ctl advance`
  /// or a scenario does: chains being recorded get an `advance` event at the new time, so a
  /// replay runs as far. Wall time: false.
  bool advance(Tick ticks);
  /// Virtual time: moves the board's time to `tick` if it is later and brings every chain
  /// there, reporting the edges of watched pins at their own ticks (a host's sleep: nothing is
  /// recorded but the edges). Wall time: false.
  bool advance_to(Tick tick);
  /// Brings every chain up to the clock, then says the earliest tick at which a watched BUSY
  /// or FLAG will change by itself (kNever: none). A host waiting for edges wakes then.
  Tick next_edge_tick();
  /// The same for one chain, from the chain's own tick (nothing is brought up to the clock).
  Tick predict_edge_tick(std::size_t chain);
  /// Current tick of chain `chain`, brought up to the clock.
  Tick now(std::size_t chain);

  // ---- the backdoor and the recordings ---------------------------------------------

  /// A backdoor event (fault on/off, thermal class, ADCIN code) on chip `chip` of chain
  /// `chain` now, recorded when the chain is being recorded; edges reported. False for a bad index.
  bool inject_fault(std::size_t chain, std::size_t chip, TraceFault fault, std::uint8_t value);
  /// Changes the load on the axis of chip `chip` now (`ctl axis load`, a scenario), recorded when
  /// the chain is being recorded; edges reported. A recording started later carries the new load
  /// in its board description. False for a bad index or a chip without an axis.
  bool set_axis_load(std::size_t chain, std::size_t chip, const LoadSpec& load);
  /// Attaches an axis to chip `chip` now (replacing one it has; Python's `attach_axis`),
  /// recorded as an `axis` event; a recording started later has it in its board description.
  /// False for a bad index.
  bool attach_axis(std::size_t chain, std::size_t chip, const AxisSpec& spec);
  /// Removes chip `chip`'s axis now, recorded. False for a bad index or a chip without one.
  bool detach_axis(std::size_t chain, std::size_t chip);
  /// Moves the hard stops of chip `chip`'s axis now (a scenario's `block:`), recorded. False
  /// for a bad index or a chip without an axis.
  bool set_axis_stops(std::size_t chain, std::size_t chip, bool has_lower, std::int64_t lower, bool has_upper,
                      std::int64_t upper);
  /// Changes the motor supply chip `chip`'s axis sees now (a scenario's `supply_mV:`; the UVLO
  /// flag is inject_fault's business), recorded. False for a bad index or a chip without an axis.
  bool set_axis_supply(std::size_t chain, std::size_t chip, std::uint32_t supply_mV);
  /// Opens the output of a recording at `path` (throws std::runtime_error with one line when it
  /// cannot). The default is open_recording_output without a clock (spi/recording_output.hpp: a
  /// plain file through a shared mapping, no system call per event; a gzip file flushed by size),
  /// what a firmware program in virtual time records through; a front may bring its own
  /// (linux/: the same, after its path checks, with gzip flushes by host time too).
  using TraceOutputOpener = std::function<std::unique_ptr<TraceOutput>(const std::string& path)>;
  /// Sets how recordings open their files (an empty function: the default). For recordings
  /// started after the call.
  void set_trace_output_opener(TraceOutputOpener opener) { open_output_ = std::move(opener); }
  /// Starts recording chain `chain` into a native trace at `path` (truncated; a recording in
  /// progress on the chain is stopped first). The header holds the chain's board description
  /// (describe_recorded_chain: variants, numbering, axes with their current loads, every other
  /// key of the description); then come every CS frame, every input pin change, every backdoor
  /// event and axis load change, every `advance`, and the BUSY/FLAG changes at their own ticks.
  /// A recording started on chips that have already run says so in the log and in the file
  /// (its replay starts them at power-up). Returns "" or one line saying why not.
  std::string start_recording(std::size_t chain, const std::string& path);
  /// Starts recording every chain: into `path` for one chain, else trace_path_for_chain files.
  std::string start_recording_all(const std::string& path);
  /// Stops recording chain `chain` (a frame still open, CS held low, is not written).
  /// Returns false when it was not recording; `summary` gets "N frames to PATH".
  bool stop_recording(std::size_t chain, std::string* summary = nullptr);
  /// Where chain `chain` is being recorded ("" = not recording).
  std::string recording_path(std::size_t chain) const;
  /// Drops every recording without writing to it again (a forked child's copies of its
  /// parent's recordings, which the parent keeps writing).
  void abandon_recordings();
  /// Hands what recordings hold to the OS when their flush policy's time has come (a gzip
  /// recording gone quiet); a front calls it now and then. Cheap when nothing is due.
  void flush_recordings();

 private:
  struct ChainState;

  ChainState& state(std::size_t chain) const;
  SpiDevice& spi_of(ChainState& c);
  void apply_input(ChainState& c, std::size_t chip, Pin pin, bool level);
  void record_outputs(ChainState& c);
  /// A recording whose file failed: said once in the log, and the chain goes on without it.
  void drop_failed_recording(ChainState& c);
  /// CS is about to rise on a chain whose CS a front drives: the frame's pin-level rules.
  void spi_frame_ends(ChainState& c);
  bool change_axis(std::size_t chain, std::size_t chip, bool needs_axis,
                   const std::function<void(RecordingChain&)>& recorded, const std::function<void(Chip&)>& direct,
                   const std::function<void(std::vector<std::pair<std::size_t, AxisSpec>>&, std::size_t)>& describe);
  void catch_up(ChainState& c);
  /// Brings the chain to `target` (if later), applying its trains' edges up to it.
  void bring_to(ChainState& c, Tick target);
  /// bring_to with trains: edge by edge where it must, else in bulk (board_pulses.cpp).
  void run_trains(ChainState& c, Tick target);
  void advance_chain(ChainState& c, Tick target);
  void advance_chain_to(ChainState& c, Tick target);
  Tick first_change(ChainState& c, std::size_t chip, Pin pin, bool level, Tick from, Tick to);
  Tick predict_next_edge(ChainState& c);
  void emit_changes(ChainState& c, Tick tick);
  bool level_of(const ChainState& c, std::size_t chip, Pin pin) const;
  void set_watch(std::size_t chain, std::size_t chip, Pin pin, bool on, bool observer);
  void install_command_sink(ChainState& c, std::size_t chip);

  LineSink log_;
  Sanitizer sanitizer_;
  EdgeSink edge_sink_;
  EdgeSink observer_sink_;
  BoardTime time_;
  NumberFrom numbering_ = NumberFrom::miso;
  BoardConfig config_;  // the description (board-wide keys) a recording's header carries
  TraceOutputOpener open_output_;
  std::unordered_map<unsigned, Tick> bus_free_;  // bus number -> tick its last use ends
  // Per chain and chip: the host's last read of BUSY ([0]) and FLAG ([1]), kNever when none.
  std::vector<std::vector<std::array<Tick, 2>>> output_reads_;
  std::unique_ptr<CoverageCollector> coverage_;  // while coverage is collected
  std::vector<std::unique_ptr<ChainState>> chains_;
  PulseTrainCounts train_counts_;
};

}  // namespace l6470emu
