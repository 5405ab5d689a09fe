// The machine a firmware program runs on, on the desktop: one thread, virtual time on a Board,
// microcontroller pins wired as the board description says, interrupts, the cost of each HAL
// call and the run's time limit. The Arduino, STM32 HAL and C fronts are thin layers over it.
// No threads, no file descriptors, no wall clock: only the Board's time.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "board/board.hpp"
#include "board/board_config.hpp"
#include "board/pin_map.hpp"
#include "board/run_report.hpp"
#include "board/scenario.hpp"
#include "firmware/arduino_board.hpp"
#include "firmware/timers.hpp"

namespace l6470emu {

class ScenarioRunner;

/// Which API a program uses: decides the default pin map and how SPI controllers are named
/// after their bus (docs/firmware.md, "The pin map").
enum class FirmwareFront { arduino, stm32_hal, c_api };

/// A pin's mode as the program set it (pinMode, HAL_GPIO_Init).
enum class McuPinMode : std::uint8_t { input, input_pullup, input_pulldown, output, output_open_drain };

/// Edges of a pin's level, as a bit set.
enum EdgeBits : unsigned { kEdgeRising = 1, kEdgeFalling = 2, kEdgeBoth = 3 };

/// The microcontroller of a firmware run and the board around it. Every front call goes through
/// call() (its cost, then pending interrupts); delays through sleep_until(). Not thread-safe
/// (a firmware program has one thread; interrupts run inside calls).
class FirmwareRuntime {
 public:
  /// A pin is named by a key: an Arduino pin number (0 to 127), or 128 + port × 16 + pin for an
  /// STM32 port pin (PA0 = 128). key_of / pin_of convert.
  static constexpr int kPinKeys = 128 + 16 * static_cast<int>(kStm32Ports);
  static int key_of(const McuPin& pin) {
    return pin.kind == McuPin::Kind::arduino ? pin.number : 128 + pin.number;
  }
  static McuPin pin_of(int key) {
    return key < 128 ? McuPin{McuPin::Kind::arduino, static_cast<std::uint16_t>(key)}
                     : McuPin{McuPin::Kind::stm32, static_cast<std::uint16_t>(key - 128)};
  }

  /// The board of `config` in virtual time, with `front`'s default pin map when the description
  /// names no pin, and (Arduino front) the description's Arduino pin numbers wired as
  /// `arduino_board` has them (map_arduino_header). Diagnostics go to `log`. Throws
  /// std::invalid_argument (one line) when the description cannot run as firmware (a socket=,
  /// wall-time scale=, two controllers of one name).
  FirmwareRuntime(const BoardConfig& config, FirmwareFront front, LineSink log,
                  ArduinoBoard arduino_board = ArduinoBoard::uno);
  ~FirmwareRuntime();
  FirmwareRuntime(const FirmwareRuntime&) = delete;
  FirmwareRuntime& operator=(const FirmwareRuntime&) = delete;

  FirmwareFront front() const { return front_; }
  /// The Arduino board whose pin numbering the program uses (an Uno unless it says otherwise).
  ArduinoBoard arduino_board() const { return arduino_board_; }
  /// The key of Arduino pin number `pin` on that board (arduino_pin_key).
  int arduino_pin(int pin) const { return arduino_pin_key(arduino_board_, pin); }
  const FirmwareTiming& timing() const { return timing_; }
  Board& board() { return *board_; }
  /// The description the run uses, with the default pin map filled in when it named no pin.
  const BoardConfig& config() const { return config_; }

  // ---- time ---------------------------------------------------------------------------------

  /// The virtual time, in ticks since the program started (250 ns each).
  Tick now() const { return now_; }
  /// One HAL call: its cost (call_time=) passes, then the pending interrupts run (unless
  /// disabled or already inside one). Ends the run at the time limit.
  void call();
  /// The same with a cost of its own (loop_time= between loop() iterations; 0 = none).
  void spend(Tick ticks);
  /// Waits until `tick` (a delay): an interrupt runs at its edge's tick on the way. Ends the
  /// run at the time limit.
  void sleep_until(Tick tick);

  // ---- pins ---------------------------------------------------------------------------------

  void set_pin_mode(int key, McuPinMode mode);
  McuPinMode pin_mode(int key) const;
  /// Sets the pin's output latch (the level it drives as an output; as an input on an Arduino,
  /// HIGH also turns the pull-up on).
  void write_pin(int key, bool level);
  /// The output latch as last written.
  bool pin_latch(int key) const;
  /// The level the pin reads now (docs/firmware.md, "The pin map": wired BUSY/FLAG read low when
  /// any chip pulls them low; an unconnected input reads its pull-up or low).
  bool read_pin(int key);
  /// Whether the description wires anything to the pin.
  bool pin_wired(int key) const;
  /// Watches the pin's level: `on_edge(level)` runs (inside the runtime, at the first call at or
  /// after the edge's tick, before pending interrupts are delivered) for every edge in `edges`.
  /// It must only mark an interrupt pending. `edges` 0 removes the watch. A level watch
  /// (`level_watch`) instead calls `on_edge(level)` at every call while the pin reads `level`.
  void watch_pin(int key, unsigned edges, std::function<void(bool level)> on_edge);
  void watch_level(int key, bool level, std::function<void(bool level)> on_level);
  /// Waits until the pin reads `level` or until `until`, whichever comes first (interrupts run
  /// on the way); true when it reads `level`. A chip output is caught at its exact edge.
  bool wait_for_level(int key, bool level, Tick until);
  /// Every pin the description wires, by key.
  std::vector<int> wired_pins() const;

  // ---- interrupts ---------------------------------------------------------------------------

  /// A new interrupt source whose handler is `handler`; returns its number (in priority order
  /// among ones pending since the same tick). Enabled when made.
  int add_irq(std::function<void()> handler);
  void set_irq_enabled(int irq, bool enabled);
  bool irq_enabled(int irq) const;
  /// Marks the interrupt pending (as of now); it runs at the next delivery.
  void pend_irq(int irq);
  void clear_irq(int irq);
  bool irq_pending(int irq) const;
  /// noInterrupts / __disable_irq: nothing is delivered until enable_interrupts().
  void disable_interrupts() { irqs_on_ = false; }
  /// interrupts / __enable_irq: re-enables and delivers what is pending at once.
  void enable_interrupts();
  bool interrupts_enabled() const { return irqs_on_; }
  /// Whether an interrupt handler is running (interrupts do not nest).
  bool in_interrupt() const { return in_irq_; }

  // ---- timers (firmware/timers.cpp) ---------------------------------------------------------

  /// The microcontroller's timers: their events wake delays and calls at their exact ticks.
  FirmwareTimers& timers() { return *timers_; }
  /// A timer's output on pin `key`: every chip input the description wires to the pin follows
  /// `train` (Board::drive_pulse_train); nullptr stops it, the pin low again. False when
  /// nothing is wired to the pin as a chip input.
  bool drive_pulse_train(int key, const PulseTrain* train);

  // ---- SPI ----------------------------------------------------------------------------------

  /// The controller the program calls `name` ("SPI", "SPI1", "HSPI", ...): the one whose chains
  /// say spi=`name` or whose bus is named so by default; a board with one controller answers to
  /// every name. -1 when none.
  int controller(std::string_view name) const;
  /// Names of the controllers, in bus order.
  std::vector<std::string> controller_names() const;
  /// Clocks `tx` on controller `controller` (bytes to every chain whose chip select is low;
  /// `rx` gets MISO) and lets the bytes' bus time pass. Settings other than mode 3, MSB first
  /// reach the chips as the wire gives them (Board::clock_bytes); the board's sanitizer names
  /// them and every other broken rule as check= says (check=error ends the run: check_rules).
  void transfer(int controller, const BusSettings& settings, std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx);

  // ---- Serial input -------------------------------------------------------------------------

  /// Bytes arriving at the program's Serial (a bound scenario's serial: step at its tick, the
  /// program's standard input as the front reads it), queued in arrival order until read.
  void serial_arrive(std::string_view bytes) { serial_in_.append(bytes); }
  /// How many bytes have arrived and are not read yet.
  std::size_t serial_available() const { return serial_in_.size() - serial_at_; }
  /// The next byte without taking it, or -1 when none is there.
  int serial_peek() const;
  /// Takes the next byte, or -1 when none is there.
  int serial_read();

  // ---- the run ------------------------------------------------------------------------------

  /// A diagnostic line ("l6470emu: " is added by the sink).
  void log(std::string_view line) const;
  /// Closes the recordings (each with the pins' levels at the end). Idempotent.
  void finish();
  /// Logs `why`, finishes and exits the program with `status`.
  [[noreturn]] void stop(int status, const std::string& why);
  /// How many loop() iterations the Arduino runtime has begun (for the end-of-run line).
  std::uint64_t loops = 0;

  // ---- under `l6470emu run` (firmware/run.hpp) ----------------------------------------------

  /// Binds `scenario` to the board (board/scenario_runner.hpp): from then on time moves through
  /// it (its steps act at their own ticks; a delay wakes for them) and it sees every SPI use and
  /// pin change; its serial: steps arrive at serial_arrive(). Throws std::invalid_argument (one line naming the step) when it does not fit.
  void bind_scenario(const Scenario& scenario);
  /// Ends the bound scenario at the time now (its `end` expectations judged) into `out`; false
  /// when none is bound. Idempotent.
  bool finish_scenario(ScenarioOutcome& out);
  /// The run's simulated time limit (kNever: none). Whichever of it and limit= comes first ends
  /// the program: limit= as always (status 0), the run's with the end hook told RunEnd::timeout
  /// and exit status kTimeoutExitStatus.
  void set_run_limit(Tick limit);
  /// Told the cause before the runtime ends the program itself for the run's time limit
  /// (RunEnd::timeout, no words) or for a broken rule at check=error (RunEnd::sanitizer, the
  /// report's first line). Any other end is the program's exit.
  void set_end_hook(std::function<void(RunEnd cause, std::string_view detail)> hook);
  /// Whether the program has clocked SPI bytes on the board.
  bool clocked_bytes() const { return clocked_; }

 private:
  struct Line;
  struct ChipRef {
    std::size_t chain = 0, chip = 0;
    Pin pin = Pin::BUSY;
  };
  struct Irq {
    std::function<void()> handler;
    bool enabled = true;
    bool pending = false;
    Tick since = 0;
  };
  struct Controller {
    std::string name;
    std::vector<std::size_t> chains;
  };

  Line* line(int key);
  const Line* line(int key) const;
  Line& make_line(int key);
  void wire(const BoardConfig& config);
  void set_now(Tick tick);
  void catch_up();
  void process_edges();
  bool line_level(const Line& l, bool tracked);
  void line_changed(Line& l);
  void apply_drive(Line& l);
  /// A line that is a chain's CK or SDI (sck_pin=, mosi_pin=) is driven to `drive` (0, 1, 2 released).
  void drive_spi_pins(Line& l, int drive);
  static bool wired(const Line& l);
  /// CS is about to rise on chain `chain` after a frame with no clock edge: said once (and
  /// SPI_PINS), with the pins the program drove that the description does not map.
  void unclocked_frame(std::size_t chain);
  void set_board_watch(Line& l, bool watched);
  void deliver();
  void poll_levels();
  [[noreturn]] void stop_at_limit();
  void dirty() { next_edge_ = 0; }
  void report_once(const std::string& key, const std::string& line);
  /// Under check=error, after the board has seen a broken rule: the sanitizer's report on
  /// stderr, recordings finished, exit status kSanitizerExitStatus (86), as under the preload.
  void check_rules();
  /// The bound scenario's steps fired by the SPI use or pin change just made.
  void after_change();
  /// A scenario step acted on the board: edges are taken and the next edge asked again.
  void world_acted();

  FirmwareFront front_;
  ArduinoBoard arduino_board_;
  BoardConfig config_;
  FirmwareTiming timing_;
  LineSink log_;
  std::unique_ptr<HostClock> clock_;
  std::unique_ptr<Board> board_;
  Tick now_ = 0;
  Tick next_edge_ = kNever;   // the earliest tick a watched chip output may change (0: ask the board)
  std::array<int, kPinKeys> line_of_{};   // key -> index in lines_ + 1 (0: none)
  std::vector<std::unique_ptr<Line>> lines_;
  std::vector<std::vector<std::array<int, kPinsPerChip>>> chip_line_;  // [chain][chip][pin] -> key or -1
  std::vector<std::vector<std::array<bool, kPinsPerChip>>> tracked_;   // watched chip outputs: level at the last edge
  std::size_t board_watches_ = 0;
  std::vector<PinEdge> edges_;     // reported by the board, not yet processed
  std::vector<Irq> irqs_;
  std::vector<int> polled_;        // keys watched whose level the board cannot predict (SW, level watches)
  bool irqs_on_ = true;
  bool in_irq_ = false;
  bool any_pending_ = false;
  bool finished_ = false;
  std::vector<Controller> controllers_;
  std::vector<std::string> reported_;
  std::uint64_t unmapped_writes_ = 0;             // level changes of such pins so far
  std::vector<std::uint64_t> unmapped_at_select_;  // per chain: unmapped_writes_ at its last CS falling edge
  std::vector<std::uint64_t> unclocked_frames_;    // per chain: CS frames with no clock edge
  std::unique_ptr<ScenarioRunner> scenario_;
  Tick run_limit_ = kNever;
  Tick limit_ticks_ = 0;   // the earlier of limit= and the run's limit
  std::function<void(RunEnd, std::string_view)> end_hook_;
  bool clocked_ = false;
  std::string serial_in_;      // Serial input arrived: read up to serial_at_
  std::size_t serial_at_ = 0;
  std::unique_ptr<FirmwareTimers> timers_;
  /// Moves the time to `tick` through the timer events before it, each met at its own tick
  /// (interrupts delivered there); then to `tick` itself.
  void run_timers_to(Tick tick);
};

/// millis() at `tick`: milliseconds since the start in 32 bits, wrapping at 2^32 (after 49.7
/// days) as a board's counter does.
inline std::uint32_t board_millis(Tick tick) { return static_cast<std::uint32_t>(tick / (1000 * kTicksPerMicrosecond)); }
/// micros() at `tick`: microseconds in 32 bits, wrapping at 2^32 (after 71.6 minutes).
inline std::uint32_t board_micros(Tick tick) { return static_cast<std::uint32_t>(tick / kTicksPerMicrosecond); }

/// The program's runtime, made at its first use: from L6470EMU_CHAIN (a description), else
/// L6470EMU_CONFIG (a file), else the description the program was built with
/// (l6470emu_default_board / l6470emu_default_board_file, set by l6470emu_add_sketch's BOARD),
/// else one L6470 (docs/firmware.md); L6470EMU_TRACE, L6470EMU_LOG, L6470EMU_CHECK and
/// L6470EMU_CHECK_ALLOW override trace=, log=, check= and check.allow=. Under `l6470emu run`
/// (its L6470EMU_RUN_REPORT or L6470EMU_SCENARIO set) run's L6470EMU_CHAIN comes first, over a
/// description the program gives too, and the runtime joins the run (firmware/run.hpp).
/// A description that cannot run ends the program with one line on stderr and status 2. The
/// first use decides the front; the runtime lives until the program ends and closes its
/// recordings at exit.
FirmwareRuntime& firmware_runtime(FirmwareFront front);

/// The runtime if one was made, else nullptr.
FirmwareRuntime* existing_firmware_runtime();

/// Makes the program's runtime from `description` (nullptr: as firmware_runtime does), or
/// returns nullptr with `error` (one line) when it cannot run or one exists already.
FirmwareRuntime* open_firmware_runtime(const char* description, FirmwareFront front, std::string& error);

}  // namespace l6470emu
