// The chips a chain of a board description stands for (variants with their axes, numbered as
// the description says), and the description a recording of one chain carries in its header so
// that a replay builds the same world. No OS calls.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "board/board_config.hpp"
#include "core/chip.hpp"
#include "daisychain/chain.hpp"

namespace l6470emu {

/// The chips of `chain` at power-up, chain order (0 drives MISO): each of its variant, with the
/// axis its axis.K= gives (K counted as `numbering` says).
std::vector<Chip> build_chips(const ChainConfig& chain, NumberFrom numbering);
/// The same as a Chain.
Chain build_chain(const ChainConfig& chain, NumberFrom numbering);

/// The board description a recording of `chain` on `board` carries (the text
/// describe_board_config writes, so every key of the description comes along): `chain` as the
/// only chain, with the board-wide keys of `board` except where output goes (log=, socket=,
/// trace=).
std::string describe_recorded_chain(const BoardConfig& board, const ChainConfig& chain);

/// A board description that must describe exactly one chain (a trace's `board` lines, a
/// --board file, a --chain description): the config, or one line saying what is wrong.
struct ChainDescription {
  std::optional<BoardConfig> board;  ///< with exactly one chain
  std::string error;
  const ChainConfig& chain() const { return board->chains.front(); }
};
ChainDescription parse_chain_description(std::string_view text, std::string_view origin);

}  // namespace l6470emu
