// The preload's side of `l6470emu run`: the scenario bound to the in-process board, the
// simulated time limit, and the report of why the program ended (board/run_report.hpp), written
// once per process. Inactive (every call a no-op) outside a run.
#pragma once

#include <string>

#include <string_view>

#include "core/tick.hpp"
#include "linux/device_board.hpp"
#include "board/run_report.hpp"

namespace l6470emu::preload {

/// Reads the run's environment (kRunScenarioEnv, kRunTimeoutEnv, kRunReportEnv) and binds the
/// scenario to `board`; the report is written at exit(). A scenario that cannot be read or does
/// not fit the board (run checked it; another board description in a child could differ) ends
/// the program with one line and status 2.
void start_run(DeviceBoard& board);
/// Whether this process is part of a run.
bool in_run();
/// Whether `l6470emu run` reads this process's report (and prints what ended it itself).
bool run_reads_report();
/// The next tick the world changes at: the scenario's next timed step (kNever: none).
Tick run_next_tick();
/// The run's simulated time limit (kNever: none).
Tick run_time_limit();
/// Virtual time reached `now`: at or past the time limit the run ends here (report, status
/// kTimeoutExitStatus), with what was recorded finished first.
void run_time_reached(Tick now);
/// This process exchanged SPI bytes with the board (its report is judged; one that only looked
/// at a device, like `spi-config -q`, is not).
void run_device_opened();
/// Writes this process's report once: `cause` and its words. The first cause wins (an exit()
/// after a reported deadlock adds nothing). The deadlock path calls it with RunEnd::deadlock and
/// the driver sanitizer's check=error path must call it with RunEnd::sanitizer and its finding
/// before ending the program, so that `run` can tell them apart whatever the exit status.
void end_run(RunEnd cause, std::string_view detail);
/// Whether the run made a waits directory (run_waits_directory) this process publishes its waits in.
bool run_publishes_waits();
/// Every thread of this process waits and only another process can end a wait: `text`
/// (format_process_waits) goes to its file in the run's waits directory, replacing what was there.
/// Called with the scheduler's lock held: real system calls only.
void run_publish_waits(const std::string& text);
/// A wait ended: the file goes (nothing when none was published).
void run_withdraw_waits();
/// fork(): the child reports for itself (it has opened nothing yet).
void run_after_fork_child();
/// Whether this process exchanged SPI bytes with the board.
bool run_devices_used();
/// A campaign's snapshot child (linux/preload/fork_server.hpp): from now on this process is a
/// rerun whose report goes to `report_path`.
void run_continue_as_rerun(const std::string& report_path);
/// The program has a board of its own that takes part in the run and reports for the process
/// (a firmware program, firmware/run.hpp): the preload's board leaves the run (no report, no time
/// limit of its own). Reached from the program through l6470emu_preload_leave_run().
void leave_run();

}  // namespace l6470emu::preload

/// The one function the preload exports besides the C library's it replaces (exports.map): a
/// firmware program under `l6470emu run` calls it, through a weak reference, when its own
/// runtime takes the run over (preload::leave_run; firmware/run.hpp). Returns the process's id
/// (getpid()) for the firmware's report block. Harmless outside a run.
extern "C" long l6470emu_preload_leave_run(void);
