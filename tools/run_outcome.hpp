// How one `l6470emu run` ended, as `run --outcome FILE` writes it for `campaign`: the exit status,
// how the program ended and each failed expectation. A small JSON object; nothing else.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "board/scenario.hpp"

namespace l6470emu {

/// What a run came to.
struct RunOutcome {
  int status = 0;            ///< run's exit status (board/run_report.hpp's RunStatus)
  bool exited = false;       ///< the program exited (else it was killed by `signal`)
  int code = 0;              ///< its exit code when it exited
  int signal = 0;            ///< the signal that killed it, 0 when none
  Tick end_tick = 0;         ///< the board's time at the end
  std::string ended;         ///< "exited with status 0", "deadlocked in virtual time", ...
  std::vector<std::string> detail;  ///< the cause in words (the deadlock report, the sanitizer's finding)
  std::vector<ScenarioFailure> failures;
  /// The program's last read of each chip's BUSY and FLAG pins it read (the latest over its processes).
  std::vector<ScenarioOutcome::PinRead> pin_reads;
};

/// Writes `o` to `path` as JSON; false when the file cannot be written.
bool write_run_outcome(const std::string& path, const RunOutcome& o);
/// Reads it back; nullopt when the file is missing or not such an object.
std::optional<RunOutcome> read_run_outcome(const std::string& path);

}  // namespace l6470emu
