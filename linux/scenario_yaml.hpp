// Writing a scenario back as a scenario file (YAML that linux/scenario_file reads into the same
// steps): what a campaign's reruns and their reproducers are made of. Writes only; reading and
// checking are scenario_file's business.
#pragma once

#include <string>
#include <string_view>

#include "board/scenario.hpp"

namespace l6470emu {

/// A duration as scenario files write it, exactly: whole seconds and up to eight decimals
/// ("0.00000025s" is one tick, "1.5s", "0s").
std::string scenario_duration_text(Tick ticks);

/// The scenario as a file `parse_scenario_yaml` reads back to the same name, timeout and steps
/// (every step but its `where`, which becomes the new file's line). `comments` are written as
/// `#` lines at the top (each step's own `where` is kept as a comment on the step).
std::string scenario_yaml(const Scenario& scenario, std::string_view comments = {});

}  // namespace l6470emu
