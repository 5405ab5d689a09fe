// The L6470EMU_* environment variables: every name some part of l6470emu reads, and the line
// that names a mistyped one with its near miss (the preload and firmware programs print it at
// start-up). Names only: the fronts read the values themselves.
#pragma once

#include <string>
#include <string_view>

namespace l6470emu {

/// The L6470EMU_* variables the preload, firmware programs, `run` and the tools read (nullptr-ended).
const char* const* known_environment_variables();

/// One line per L6470EMU_* variable of `env` (a nullptr-ended environ) that nothing reads,
/// naming the closest known one and what `reader` reads ("the preload reads L6470EMU_CHAIN,
/// ..."); "" when there is none.
std::string unknown_environment_variables(char** env, std::string_view reader);

}  // namespace l6470emu
