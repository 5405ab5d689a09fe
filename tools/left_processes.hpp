// The processes a program run by `l6470emu run` leaves behind when it ends: its children still
// running, and their descendants, setsid() ones included (a setsid() grandchild leaves the
// program's process group and session, so no signal to a group reaches it). This process is
// made their reaper (prctl PR_SET_CHILD_SUBREAPER): the kernel hands every orphaned descendant
// of the program to it rather than to init, and `run` can wait for them and end them. Linux only.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace l6470emu {

/// Makes this process the reaper of the orphaned descendants of the programs it starts from now
/// on, and remembers which children it has already (they are not the program's). Call before
/// starting the program. False when the kernel refuses (then orphans go to init, as before).
bool adopt_orphans_from_now();

/// This process's children (pids, zombies included), read from /proc.
std::vector<pid_t> child_processes();

/// What end_left_processes did.
struct LeftProcesses {
  std::vector<std::string> running;  ///< "PID NAME" of each one still running after the grace period
  bool killed = false;               ///< SIGTERM was not enough: SIGKILL ended some
  std::size_t unended = 0;           ///< still running when it gave up (a process that keeps forking)
  /// One line for `run` to say ("" when nothing was left running).
  std::string line(std::chrono::milliseconds grace) const;
};

/// After the program ended (and was waited for): reaps the children it left that ended by
/// themselves within `grace`, then ends the rest with SIGTERM, and with SIGKILL those still
/// there `term_grace` later, their own orphans too, until none is left (at most a few seconds
/// more). Children this process had before adopt_orphans_from_now() are left alone.
LeftProcesses end_left_processes(std::chrono::milliseconds grace,
                                 std::chrono::milliseconds term_grace = std::chrono::seconds(2));

}  // namespace l6470emu
