// L6470EMU_COVERAGE=FILE in a preloaded program: the board collects interface coverage, and the
// process merges what it met into FILE when it ends (its exit, or the preload's own ends: a
// time limit, a deadlock, a sanitizer error), so that every process of a run lands in the file.
#pragma once

#include <string>

#include "linux/device_board.hpp"

namespace l6470emu::preload {

/// Checks L6470EMU_COVERAGE when the library loads: "" (unset, or a file that can take
/// coverage) or one line saying why not (the program is then stopped with it, status 2).
std::string check_coverage_environment();
/// With L6470EMU_COVERAGE set: starts collecting on `board` and merges at exit.
void start_coverage(DeviceBoard& board);
/// Merges what this process met into the file, once per process (later calls do nothing).
void finish_coverage();
/// After fork() in the child: the child merges what it meets too, at its own end.
void coverage_after_fork_child();

}  // namespace l6470emu::preload
