// Reading /proc for `run`'s looks at the program's processes (run_waits, run_blocked): which
// directory entries are process or thread ids, and a small file's text. Nothing else.
#pragma once

#include <cstddef>
#include <string>

namespace l6470emu {

/// Whether a /proc directory entry's name is a process (or thread) id: digits only, not empty.
bool is_pid_name(const char* name);

/// The text of a small file (a /proc entry), at most `limit` bytes; "" when it cannot be read.
std::string read_small_file(const std::string& path, std::size_t limit = 1 << 20);

}  // namespace l6470emu
