// Reading /proc for `run`'s looks at the program's processes (run_waits, run_blocked): which
// directory entries are process or thread ids (and a directory's such entries), a small file's text, the process table and the
// live descendants of a process.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace l6470emu {

/// Whether a /proc directory entry's name is a process (or thread) id: digits only, not empty.
bool is_pid_name(const char* name);

/// The names of `dir`'s entries that are process or thread ids (or descriptor numbers), in the
/// order the directory gives them; none when it cannot be read.
std::vector<std::string> numbered_entries(const std::string& dir);

/// The text of a small file (a /proc entry), at most `limit` bytes; "" when it cannot be read.
std::string read_small_file(const std::string& path, std::size_t limit = 1 << 20);

/// A process as /proc/PID/stat gives it.
struct ProcessInfo {
  pid_t parent = 0;
  char state = 0;    ///< 'R', 'S', 'Z', ...
  std::string name;  ///< the command name between the parentheses
};

/// Every process's parent, state and name (the processes whose stat could be read).
std::map<pid_t, ProcessInfo> all_processes();

/// The live (not zombie) descendants of `root` in `all`, children of children included.
std::set<pid_t> live_descendants(const std::map<pid_t, ProcessInfo>& all, pid_t root);

}  // namespace l6470emu
