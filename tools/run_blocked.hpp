// What each thread of a run's processes is blocked in, as the kernel shows it in /proc (the system
// call, its first argument when it is a descriptor, and the kernel function it sleeps in), for the
// words `run` says when its wall-clock guard ends a program virtual time could not judge. A
// fallback diagnosis, named as such: the program's own view (the preload's covered waits) is in
// the waits a process publishes (tools/run_waits.hpp), used first where there is one. Linux only.
#pragma once

#include <sys/types.h>

#include <map>
#include <string>
#include <vector>

namespace l6470emu {

/// One line per thread of every live descendant of this process: "process 12 (sh) thread 12:
/// wait4() (kernel: do_wait)", "... read() of fd 0 (pipe:[123]) (kernel: pipe_read)"; for a
/// process in `said` (the thread lines it published, RunWaits::said), those lines instead
/// ("process 12 (cat): thread 12 (cat): read() on fd 0, no timeout"). Empty when /proc shows
/// nothing.
std::vector<std::string> blocked_threads(const std::map<pid_t, std::vector<std::string>>& said = {});

}  // namespace l6470emu
