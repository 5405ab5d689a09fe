// How `l6470emu run` judges a program that ended: its wait status, the report blocks its
// processes left (board/run_report.hpp) and how run itself stopped it come to one exit status,
// the words for how it ended and what the scenario came to. `run` prints and writes its reports
// from it; `campaign` judges a rerun forked from a snapshot with it, as run would have.
#pragma once

#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

#include "board/run_report.hpp"
#include "tools/run_outcome.hpp"

namespace l6470emu {

/// How the program's run ended, as the one who waited for it saw it.
struct ProgramExit {
  pid_t pid = 0;                  ///< the program's process (its block is judged when no other is)
  int wstatus = 0;                ///< as waitpid gave it
  bool wall_timeout = false;      ///< killed at the simulated time limit, counted in wall time
  bool wall_guard = false;        ///< killed by the wall-clock guard (--wall-timeout)
  Tick wall_guard_limit = 0;      ///< that guard, in ticks of host time (for the words)
  int stopped_by = 0;             ///< a signal to run passed on to the program (0: none)
  /// Non-empty: run found every process of the program waiting on another (tools/run_waits.hpp)
  /// and ended them; what each thread waited on, one a line.
  std::vector<std::string> deadlock;
  /// What each thread of the program's processes was blocked in when the wall-clock guard ended
  /// it (tools/run_blocked.hpp), one a line.
  std::vector<std::string> blocked;
  std::vector<RunReport> blocks;  ///< one per process that wrote one
};

/// What a run came to.
struct RunJudgement {
  int status = kRunPassed;   ///< run's exit status (RunStatus, or 128 + N when run was stopped by signal N)
  std::string ended;         ///< "exited with status 0", "deadlocked in virtual time", ...
  std::string why;           ///< a note after the status words (no report left), or empty
  bool when_known = false;   ///< the end's tick is known (a report, the time limit)
  Tick end_tick = 0;
  bool exited = false;
  int code = -1;
  int signal = 0;
  std::size_t expectations = 0;  ///< expectations judged
  std::vector<ScenarioFailure> failures;
  std::vector<std::string> passed;  ///< expectations that held ("WHERE: what")
  std::vector<std::string> world;   ///< what the world did, one line each
  std::vector<std::string> detail;  ///< the cause in words (the block that ended the run)
  std::vector<ScenarioOutcome::PinRead> pin_reads;  ///< the last read of each pin, over the processes

  /// As `run --outcome` writes it.
  RunOutcome outcome() const;
};

/// Judges the run. `timeout` is its simulated time limit (the end's tick when killed at it).
RunJudgement judge_run(const ProgramExit& exit, std::optional<Tick> timeout);

}  // namespace l6470emu
