// Where a run's recordings are: a board of one chain records into the path it is given
// (run --record, trace=), a board of several chains into one native trace per chain beside it
// (trace_path_for_chain: "run.trace" -> "run.spidev0.1.trace"). run --html and campaign --html
// hand every chain's recording to the report page; `report` finds them from the path the run
// was given. Names and files only: reading a recording is tools/trace_input.hpp's.
#pragma once

#include <string>
#include <vector>

#include "board/board_config.hpp"

namespace l6470emu {

/// A chain's recording: the chain's name as the board names it ("spidev0.1") and the file.
struct ChainRecording {
  std::string chain;
  std::string path;
};

/// The recordings a run of `board` recording to `path` writes, in the board's chain order
/// (whether or not the program used each chain: one it never opened has no file).
std::vector<ChainRecording> run_recordings(const BoardConfig& board, const std::string& path);

/// The recordings a run of several chains recorded to `path` left beside it: the native traces
/// named as trace_path_for_chain names them whose board lines are of the chain their name says,
/// ordered by bus and chip select. Empty when there are none (or `path` is a file of its own).
std::vector<ChainRecording> find_run_recordings(const std::string& path);

}  // namespace l6470emu
