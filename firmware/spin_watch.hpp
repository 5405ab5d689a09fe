// The one thing single-threaded virtual time cannot see: a program spinning in its own code
// (`while (!flag);` waiting for a flag only an interrupt sets) never calls the runtime, so
// virtual time stands still and the interrupt never comes. This watch says so once, on stderr,
// after a second of the program's CPU time with no call into the runtime. It changes nothing
// the program does (POSIX interval timer on the process's CPU time, SIGPROF; nothing else).
#pragma once

#include <cstdint>

namespace l6470emu {

/// Starts watching `calls` (the runtime's count of entries, bumped at every API call): when it
/// has not moved for kSpinWatchSeconds of the process's CPU time, `message` (one line, kept
/// by the caller for the life of the program) is written to stderr, once. A program that has a
/// SIGPROF handler of its own is left alone.
void start_spin_watch(const volatile std::uint64_t* calls, const char* message);

/// Seconds of CPU time without an entry before the watch speaks.
inline constexpr int kSpinWatchSeconds = 1;

}  // namespace l6470emu
