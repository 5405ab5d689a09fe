// The daemon's control interface (`l6470emu ctl ...`): the physical world and inspection
// without side effects, as text commands. Parsing and formatting only; the Board does the work.
#pragma once

#include <string>

#include "linux/board.hpp"

namespace l6470emu {

/// Runs one control command line (words separated by blanks) against `board`.
/// Returns the exit status for `ctl` (0 ok, 1 failed, 2 usage) and the text to print.
int run_control(Board& board, const std::string& command, std::string& output);

/// Text of `ctl help`.
std::string control_help();

}  // namespace l6470emu
