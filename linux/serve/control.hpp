// The daemon's control interface (`l6470emu ctl ...`): the physical world and inspection
// without side effects, as text commands. Parsing and formatting only; the DeviceBoard does the work.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "linux/device_board.hpp"

namespace l6470emu {

/// Runs one control command line (words separated by blanks) against `board`.
/// Returns the exit status for `ctl` (0 ok, 1 failed, 2 usage) and the text to print.
/// Chip numbers, in --chip K and in the output, count as the board's numbering() says, or as
/// `--number-from miso|mosi` in the command says; status, dump and chains say which, once.
int run_control(DeviceBoard& board, const std::string& command, std::string& output);

/// Longest `ctl advance MS`, in ms: 10^10 ms, about 115 days (4·10^13 ticks, far from the tick's range).
inline constexpr std::uint64_t kMaxAdvanceMs = 10'000'000'000;

/// Reads the MS of `ctl advance MS` exactly (no float): digits, optionally a point and at most 9
/// decimals, at most kMaxAdvanceMs. Sets `ticks` (a fraction of a tick dropped) and returns "", or
/// returns one line saying what is wrong with the text (inf, nan, 1e3, -1 and 4e15 included).
std::string parse_advance_ms(const std::string& text, Tick& ticks);

/// Text of `ctl help`: with `numbering`, the daemon's convention; without, a client that has
/// not asked the daemon (which numbers as its numbering= says).
std::string control_help(std::optional<NumberFrom> numbering = std::nullopt);

/// The commands `ctl` takes (its first word), as control_help lists them.
const std::vector<std::string>& control_commands();
/// "unknown command 'statsu'; did you mean status?" (without the near miss when none is close).
std::string unknown_control_command(const std::string& word);

}  // namespace l6470emu
