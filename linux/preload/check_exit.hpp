// What the preload does at the edges of a host program's run that the board cannot see: the
// driver sanitizer's end of a run (check=error), the L6470EMU_* variables it does not know,
// and opens of device nodes the board does not have. No interception here.
#pragma once

#include <string>
#include <string_view>

namespace l6470emu::preload {

/// Ends the host program's run for a broken rule of the chip (check=error): writes `report`
/// to stderr and the log, then _exit(kSanitizerExitStatus) (board/check_rules.hpp). Like a
/// sanitizer's exit: no atexit handlers or stdio flushes run (another thread may hold their locks).
[[noreturn]] void end_run_for_check(const std::string& report);

/// An open() of `path` that is no node of the board: once per path, when it looks like a spidev
/// or gpiochip node, a log line saying which nodes the board has.
void note_missing_node(const char* path);

}  // namespace l6470emu::preload
