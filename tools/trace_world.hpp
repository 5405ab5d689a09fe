// The emulated world a trace runs through for replay, decode, convert and plot: the board
// description of one chain (variants, numbering, axes with their switches and loads, every
// other key), taken from the trace's own header or given by the user (--board FILE, --chain
// with a description), or only variants (--chain 3*L6470, a trace's chain line, a guess).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "board/board_config.hpp"
#include "daisychain/chain.hpp"
#include "spi/trace.hpp"
#include "tools/trace_input.hpp"

namespace l6470emu {

/// What the user gave for the world.
struct WorldOptions {
  /// --chain: variants ("3", "2*L6470,L6480") or a board description of one chain ("chips=L6470
  /// axis.0=stops=0..256000,switch=home@0"); empty = not given.
  std::string chain;
  /// --board: a file holding the board description of one chain; empty = not given.
  std::string board_file;
};

/// The world a trace runs through.
struct TraceWorld {
  BoardConfig board;  ///< exactly one chain
  std::string how;    ///< where it came from, in words ("from the trace's board description")
  /// An explicit description replaced the trace's own (its `board` or `chain` lines).
  bool overrides = false;
  std::string overridden;  ///< what the trace's own said ("3*L6470" or its board description), when overrides

  const ChainConfig& chain() const { return board.chains.front(); }
  /// The chips at power-up: variants, and the axes behind them.
  Chain make_chain() const;
  /// "2*L6470" or "2*L6470 with an axis behind chip 1" (numbered as the description says).
  std::string summary() const;
  /// The description as board lines for a native header ("" when it holds only variants and
  /// nothing else a replay would need).
  std::string board_text() const;
  /// One line saying that an explicit description was used instead of the trace's own ("" when not).
  std::string override_note(const std::string& trace_name) const;
};

/// The world of a trace with header `header`: `options` when given, else the trace's `board`
/// lines, else its `chain` line, else `guess()` (variants guessed from frame lengths; a null
/// function: ValueError-style std::invalid_argument asking for one). Throws TraceError naming
/// the trace's line, --chain or the --board file for a malformed description.
TraceWorld world_for_header(const WorldOptions& options, const TraceHeader& header,
                            const std::function<std::vector<const Variant*>(std::string& how)>& guess);

/// The same for a trace file: the guess is as many L6470s as its most common frame length.
TraceWorld world_for_trace(const WorldOptions& options, const TraceFile& file);

}  // namespace l6470emu
