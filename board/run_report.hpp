// What a program run by `l6470emu run` tells `run` when it ends: why it ended (its exit, the
// run's time limit, a virtual-time deadlock, a sanitizer error) and what its scenario came to.
// Each front that runs programs (the preload, linux/preload/run.cpp; the firmware runtime,
// firmware/run.cpp) appends one block per process to the file run names in L6470EMU_RUN_REPORT;
// this file is the block's text and run's exit statuses (docs/scenarios.md), nothing else: the
// fronts write the file themselves.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "board/scenario.hpp"

namespace l6470emu {

/// The environment a run gives its program (besides L6470EMU_CHAIN / L6470EMU_CONFIG).
inline constexpr const char* kRunReportEnv = "L6470EMU_RUN_REPORT";      ///< file the blocks are appended to
inline constexpr const char* kRunScenarioEnv = "L6470EMU_SCENARIO";      ///< the scenario in exchange form (a file)
inline constexpr const char* kRunTimeoutEnv = "L6470EMU_TIMEOUT_TICKS";  ///< simulated time limit, 250 ns ticks
/// A file of kRunProgressBytes the program maps and keeps RunProgress in, for run's progress line.
inline constexpr const char* kRunProgressEnv = "L6470EMU_RUN_PROGRESS";

/// How far a program has come, as its front keeps it in the kRunProgressEnv file (two
/// little-endian 64-bit words, each stored whole).
struct RunProgress {
  std::uint64_t tick = 0;      ///< the board's time
  std::uint64_t messages = 0;  ///< SPI messages exchanged with the board
};
inline constexpr std::size_t kRunProgressBytes = 16;

/// The exit status of a program whose run reached its simulated time limit (the report says so;
/// like kDeadlockExitStatus, only a fallback when no report could be written).
inline constexpr int kTimeoutExitStatus = 87;

/// `l6470emu run`'s exit statuses, one per way a run can end (docs/scenarios.md).
enum RunStatus : int {
  kRunPassed = 0,               ///< the program exited 0 and every expectation held
  kRunExpectationFailed = 1,    ///< an expectation failed (or a step's trigger never came)
  kRunUsage = 2,                ///< usage, board description or scenario error: the program never started
  kRunTimedOut = 3,             ///< the simulated time limit (--timeout, the scenario's timeout:) was reached
  kRunDeadlocked = 4,           ///< virtual time found every thread waiting with nothing to wake them
  kRunSanitizerError = 5,       ///< the driver sanitizer (check=error) found a broken rule
  kRunProgramFailed = 6,        ///< the program exited non-zero or was killed by a signal
  kRunNotStarted = 7,           ///< the program could not be started, or ended without a report
};

/// Why the program ended.
enum class RunEnd : std::uint8_t { exit, timeout, deadlock, sanitizer };
std::string_view to_string(RunEnd end);

/// One process's block.
struct RunReport {
  std::int64_t pid = 0;               ///< the process (a pid_t)
  RunEnd end = RunEnd::exit;
  Tick tick = 0;                      ///< the board's time at the end
  bool devices = false;               ///< the process exchanged SPI bytes with the board
  bool scenario = false;              ///< a scenario was bound to its board
  std::vector<std::string> detail;    ///< the cause in words (the deadlock report, the sanitizer's finding)
  ScenarioOutcome outcome;
};

/// The non-empty lines of `text` (a deadlock report, a sanitizer's finding), as RunReport::detail holds them.
std::vector<std::string> detail_lines(std::string_view text);

/// The block's text (lines "key value", fields of a failure separated by tabs, ending in ".").
std::string format_run_report(const RunReport& r);
/// The complete blocks of `text` (a block cut short by a killed process is skipped).
std::vector<RunReport> parse_run_reports(std::string_view text);

}  // namespace l6470emu
