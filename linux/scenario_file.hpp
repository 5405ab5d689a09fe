// Reading a scenario file (YAML, through the yaml-cpp library) into board/scenario.hpp's model;
// docs/scenarios.md is the schema. Every error is one line naming the file, line and key.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "board/scenario.hpp"

namespace l6470emu {

/// A scenario read, or the first error in it.
struct ScenarioParse {
  std::optional<Scenario> scenario;
  /// "l6470emu: scenario FILE:LINE: key 'KEY': what (did you mean ...?)".
  std::string error;
};

/// The longest scenario file read (bytes); a longer one is an error.
inline constexpr std::size_t kMaxScenarioBytes = std::size_t{1} << 20;

/// Parses scenario text; `file` names it in errors and in each step's `where` ("FILE:LINE").
/// Never throws; nesting deeper than the schema allows is refused before the YAML library sees it.
ScenarioParse parse_scenario_yaml(std::string_view text, std::string_view file);

/// Reads and parses the file at `path` (at most kMaxScenarioBytes).
ScenarioParse load_scenario_file(const std::string& path);

/// A duration as scenario files write it ("250ns", "1us", "10ms", "2.5s", "1min", or a number of
/// seconds) in 250 ns ticks; nullopt when it is not one or not a whole number of ticks.
std::optional<Tick> parse_scenario_duration(std::string_view text);

}  // namespace l6470emu
