// The daemon's control interface (`l6470emu ctl ...`): the physical world and inspection
// without side effects, as text commands. Parsing and formatting only; the DeviceBoard does the work.
#pragma once

#include <optional>
#include <string>

#include "linux/device_board.hpp"

namespace l6470emu {

/// Runs one control command line (words separated by blanks) against `board`.
/// Returns the exit status for `ctl` (0 ok, 1 failed, 2 usage) and the text to print.
/// Chip numbers, in --chip K and in the output, count as the board's numbering() says, or as
/// `--number-from miso|mosi` in the command says; status, dump and chains say which, once.
int run_control(DeviceBoard& board, const std::string& command, std::string& output);

/// Text of `ctl help`: with `numbering`, the daemon's convention; without, a client that has
/// not asked the daemon (which numbers as its numbering= says).
std::string control_help(std::optional<NumberFrom> numbering = std::nullopt);

}  // namespace l6470emu
