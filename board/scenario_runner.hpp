// Running a scenario on a Board: its actions at their ticks or events, through the Board's own
// backdoor calls (so a recording carries them), and the judging of its expectations. Knows no
// thread, file or process: a front calls advance_to / after_transfer / finish.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "board/board.hpp"
#include "board/scenario.hpp"

namespace l6470emu {

/// A scenario bound to a board. Construction checks the scenario against the board (chains,
/// chip numbers, register, command and STATUS flag names, axes where an action needs one) and
/// throws std::invalid_argument with one line naming the step ("FILE:LINE: ...") on the first
/// mismatch. While it lives it owns the board's observer sink and the chips' command sinks.
///
/// Time: the front moves the board's time through advance_to() instead of Board::advance_to;
/// it brings the board to every tick a step fires at (a timed step, a BUSY edge, the exact tick
/// a position is reached) and applies the step there, so that the world acts at its own time
/// whatever the host waits for. Steps fired by a command are applied by after_transfer(), at
/// the end of the SPI use that carried the command.
///
/// Serial steps (`serial: "text"`) go to `serial_input`, the program's Serial as its front
/// gives it (a firmware sketch's); without one (a program under the preload) such a step fails
/// when it fires, named, as a program with no Serial to read it.
class ScenarioRunner {
 public:
  /// Where a serial step's bytes go: the program's Serial input.
  using SerialInput = std::function<void(std::string_view bytes)>;

  ScenarioRunner(Board& board, Scenario scenario, SerialInput serial_input = {});
  ~ScenarioRunner();
  ScenarioRunner(const ScenarioRunner&) = delete;
  ScenarioRunner& operator=(const ScenarioRunner&) = delete;

  /// The earliest tick at which a timed step is due (kNever: none). A host waiting in virtual
  /// time must wake then even if it waits for nothing else.
  Tick next_tick() const;
  /// Virtual time: moves the board to `target`, firing the steps due on the way.
  void advance_to(Tick target);
  /// Applies the steps fired by commands or edges seen during the last SPI use or pin change.
  void after_transfer();
  /// Wall time: fires the steps due at the board's time now (late by however long the host
  /// took to call).
  void poll();
  /// The program ended at the board's time: judges the `end` expectations and every BUSY
  /// pulse expectation; steps not yet fired are reported as never reached. Idempotent.
  void finish();

  /// Adds `steps` to the scenario while it runs (a campaign's rerun forked from a snapshot of the
  /// run: the fault's steps and the oracle). Only steps at a time or at the end can join: events
  /// before now were not counted. Checked against the board as at construction (throws
  /// std::invalid_argument, nothing added); steps due now fire at once.
  void add_steps(const std::vector<ScenarioStep>& steps);

  const std::vector<ScenarioFailure>& failures() const { return failures_; }
  /// Expectations judged so far (passed and failed).
  std::size_t judged() const { return judged_; }
  /// What the world did and what was judged, one line each ("0.100000 s: spidev0.0 chip 1: SW closed").
  const std::vector<std::string>& log() const { return log_; }
  /// Expectations that held, as "WHERE: what" (for the JUnit report).
  const std::vector<std::string>& passed() const { return passed_; }
  const Scenario& scenario() const { return scenario_; }
  /// What it came to so far (after finish(): at the program's end).
  /// What the scenario came to so far, with the host's last reads of every BUSY and FLAG pin.
  ScenarioOutcome outcome() const;

 private:
  struct Resolved {
    std::size_t chain = 0;
    std::size_t chip = 0;
    std::string label;  // "spidev0.0 chip 1"
  };
  struct StepState {
    bool done = false;
    std::uint32_t seen = 0;         // events counted toward `count`
    Resolved trigger_chip;
    Resolved target_chip;           // action or expectation
    std::int64_t start_side = 0;    // position triggers: sign of (position - target) when armed
    bool armed = false;
    Tick due = kNever;              // an event with a delay came: the step happens then
  };
  struct Pulse {
    Tick start = 0;
    Tick end = kNever;
  };

  Resolved resolve(const ScenarioChip& c, const std::string& where) const;
  // Checks step i against the board (throws std::invalid_argument) and resolves its chips; BUSY
  // pins it needs watched are added to `busy_watch`.
  void check_step_against_board(std::size_t i, std::vector<std::pair<std::size_t, std::size_t>>& busy_watch);
  void check_step(std::size_t i);
  bool pending_events() const;
  bool pending_positions() const;
  Tick position_reached_within(std::size_t i, Tick from, Tick to);
  std::int64_t position_of(const Chip& chip, bool true_position) const;
  void fire(std::size_t i, Tick tick);
  void triggered(std::size_t i, Tick tick);  // the event came: fire now or after its delay
  void apply(const ScenarioAction& a, const Resolved& r, const std::string& where);
  void judge(const ScenarioExpectation& e, const Resolved& r, const std::string& where, Tick tick);
  void fail(const std::string& where, const std::string& what, Tick tick, const Resolved& r, std::string expected,
            std::string seen);
  void pass(const std::string& where, const std::string& what);
  void take_events(Tick now);
  void fire_due_times(Tick now);
  void fire_positions(Tick now);

  Board& board_;
  Scenario scenario_;
  SerialInput serial_input_;
  std::vector<StepState> state_;
  std::vector<ScenarioFailure> failures_;
  std::vector<std::string> log_;
  std::vector<std::string> passed_;
  std::size_t judged_ = 0;
  bool finished_ = false;
  // What the sinks saw, taken up by take_events().
  struct Seen {
    std::size_t chain, chip;
    bool busy_edge;
    bool level;          // BUSY edges
    std::string command; // commands
    Tick tick;
  };
  std::vector<Seen> seen_;
  // per chain: per chip: BUSY pulses and command counts
  std::vector<std::vector<std::vector<Pulse>>> pulses_;
  std::vector<std::vector<std::vector<std::pair<std::string, std::uint64_t>>>> commands_;
  std::vector<std::vector<bool>> uvlo_by_supply_;
};

}  // namespace l6470emu
