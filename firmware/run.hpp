// The firmware front's side of `l6470emu run`: the run's scenario bound to the program's own
// board, the run's simulated time limit, and the report block (board/run_report.hpp) appended at
// exit, as the preload does for a Linux program (linux/preload/run.hpp). Inactive outside a run.
#pragma once

#include <string>

namespace l6470emu {

class FirmwareRuntime;

/// Reads the run's environment (kRunScenarioEnv, kRunTimeoutEnv, kRunReportEnv); when any is set
/// the runtime takes part in the run: the scenario bound to its board, the time limit set, and
/// one report block appended at exit whatever ends the program (its return or exit(), limit=,
/// the run's limit, a broken rule at check=error). The preload library run loads into every
/// program is told to leave the run to the firmware's board (l6470emu_preload_leave_run).
/// Returns "" or, when the run cannot be joined (the scenario cannot be read or does not fit the
/// board, the limit is not a number of ticks), one line: the caller ends the program with it and
/// status kRunUsage (2).
std::string join_run(FirmwareRuntime& runtime);

}  // namespace l6470emu
