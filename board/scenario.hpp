// A scenario: what the world does to a board and what must be seen of it (docs/scenarios.md),
// as plain data, and its exchange form between `l6470emu run` and the program it runs. Reading
// YAML is linux/scenario_file's business; running one is board/scenario_runner's.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/axis_spec.hpp"
#include "core/tick.hpp"
#include "spi/trace.hpp"

namespace l6470emu {

/// A chip as the user names it: a chain (its name, "" = the board's first) and the chip's
/// number in the board's numbering (numbering=).
struct ScenarioChip {
  std::string chain;
  std::size_t number = 0;
  friend bool operator==(const ScenarioChip&, const ScenarioChip&) = default;
};

/// When a step happens.
struct ScenarioTrigger {
  enum class Kind : std::uint8_t {
    time,           ///< at `tick`
    end,            ///< when the program ends (expectations only)
    position,       ///< ABS_POS of `chip` reaches `position` (microsteps, as the register counts)
    true_position,  ///< the rotor of `chip`'s axis reaches `position` (1/128 step)
    busy_fall,      ///< BUSY of `chip` goes low (a command starts running)
    busy_rise,      ///< BUSY of `chip` goes high (it ended)
    command,        ///< `chip` decodes command `command`
  };
  Kind kind = Kind::time;
  Tick tick = 0;              ///< time: when; events: not before this tick
  ScenarioChip chip;          ///< events
  std::int64_t position = 0;  ///< position, true_position
  std::string command;        ///< command: datasheet name ("GoUntil")
  std::uint32_t count = 1;    ///< events: the Nth occurrence (from `tick` on) fires
  Tick delay = 0;             ///< events: the step happens this long after the event
  friend bool operator==(const ScenarioTrigger&, const ScenarioTrigger&) = default;
};

/// Something the world does to one chip, or (serial) types into the program's Serial.
struct ScenarioAction {
  enum class Kind : std::uint8_t {
    sw,        ///< the switch on SW closes (level low) or opens (high): `level`
    stby_rst,  ///< STBY\RST driven to `level` (low = standby/reset)
    fault,     ///< a backdoor event: `fault` with `value` (as the native trace carries them)
    load,      ///< the axis's load becomes `load`
    block,     ///< a hard stop at `position` (1/128 step) on the side the rotor is moving to
    supply,    ///< the motor supply becomes `supply_mV`; UVLO follows the L6470's thresholds
    serial,    ///< `text` arrives at the program's Serial input (a firmware sketch's); no chip
    dir,       ///< DIR (an L6474's) driven to `level` (high = forward: the way STCK then steps)
  };
  Kind kind = Kind::sw;
  ScenarioChip chip;
  bool level = false;
  TraceFault fault = TraceFault::OCD;
  std::uint8_t value = 1;
  LoadSpec load;
  std::int64_t position = 0;
  std::uint32_t supply_mV = 12'000;
  std::string text;  ///< serial: the bytes, as they are
  friend bool operator==(const ScenarioAction&, const ScenarioAction&) = default;
};

/// Something that must be seen.
struct ScenarioExpectation {
  enum class Kind : std::uint8_t {
    reg,            ///< register `name` of `chip` is `value` ± `tolerance` (signed ones sign-extended)
    true_position,  ///< the rotor of `chip` is at `value` ± `tolerance` (1/128 step)
    status,         ///< STATUS bits of `chip` (without the side effects of reading): `flags`
    busy_pulse,     ///< BUSY pulses of `chip` (the `pulse`th, 0 = every one) last min..max ticks
    command,        ///< `chip` decoded command `name` `count` times (sent: count ≥ 1; not sent: 0)
    frames,         ///< the chain of `chip` saw min..max CS frames
    sanitizer,      ///< no rule of the driver sanitizer fired on the board (allowed rules and check=off: none fire)
  };
  Kind kind = Kind::reg;
  ScenarioChip chip;
  std::string name;                 ///< reg: register name; command: command name
  std::int64_t value = 0;           ///< reg, true_position
  std::int64_t tolerance = 0;       ///< reg, true_position
  /// status: (flag name, bit value as STATUS reads it), e.g. ("OCD", 0) for an overcurrent.
  std::vector<std::pair<std::string, bool>> flags;
  Tick min_ticks = 0;               ///< busy_pulse
  Tick max_ticks = kNever;          ///< busy_pulse
  std::uint32_t pulse = 0;          ///< busy_pulse
  /// command: exact count wanted; kAtLeastOnce = "sent" (one or more); 0 = "not sent".
  std::uint64_t count = kAtLeastOnce;
  std::uint64_t min_count = 0;      ///< frames
  std::uint64_t max_count = UINT64_MAX;  ///< frames
  static constexpr std::uint64_t kAtLeastOnce = UINT64_MAX;
  friend bool operator==(const ScenarioExpectation&, const ScenarioExpectation&) = default;
};

/// One step: a trigger and either an action or an expectation.
struct ScenarioStep {
  std::string where;  ///< "FILE:LINE" of the step, for reports
  ScenarioTrigger when;
  std::optional<ScenarioAction> action;
  std::optional<ScenarioExpectation> expect;
  friend bool operator==(const ScenarioStep&, const ScenarioStep&) = default;
};

/// A whole scenario.
struct Scenario {
  std::string name;                  ///< for reports ("" = the file's name)
  std::optional<Tick> timeout_ticks; ///< the file's `timeout:` (run's --timeout wins)
  std::vector<ScenarioStep> steps;
  friend bool operator==(const Scenario&, const Scenario&) = default;
};

/// A failed expectation: what, when, which chip, expected and seen.
struct ScenarioFailure {
  std::string where;     ///< "FILE:LINE" of the step
  std::string what;      ///< "ABS_POS", "STATUS.OCD", "BUSY pulse 2", "command GoUntil", "frames"
  Tick tick = 0;         ///< when it was judged
  std::string chip;      ///< "spidev0.0 chip 1"
  std::string expected;
  std::string seen;
};

/// What a scenario came to when the program ended (ScenarioRunner::outcome).
struct ScenarioOutcome {
  /// The host's last read of a chip's BUSY or FLAG pin (Board::last_output_read).
  struct PinRead {
    std::string chain;     ///< "spidev0.0"
    std::size_t chip = 0;  ///< as users number it
    std::string pin;       ///< "BUSY" or "FLAG"
    Tick tick = 0;
  };
  std::size_t judged = 0;                  ///< expectations judged
  std::vector<ScenarioFailure> failures;   ///< those that failed
  std::vector<std::string> passed;         ///< "WHERE: what" of those that held
  std::vector<std::string> log;            ///< what the world did, one line each
  std::vector<PinRead> pin_reads;          ///< every chip's pins the host read, at its last read
};

/// The exchange form (JSON, one object) `run` hands the program's preload library.
std::string serialize_scenario(const Scenario& s);
/// Reads serialize_scenario's form back; nullopt and `error` (one line) when it is not that.
std::optional<Scenario> deserialize_scenario(std::string_view text, std::string& error);

/// Names: "sw", "stby_rst", "fault", "load", "block", "supply", "serial"; triggers and expectations alike.
std::string_view to_string(ScenarioAction::Kind k);
std::string_view to_string(ScenarioTrigger::Kind k);
std::string_view to_string(ScenarioExpectation::Kind k);

/// "1.250000 s".
std::string seconds_text(Tick tick);

}  // namespace l6470emu
