// Whether another process could still make a descriptor readable: the deadlock rule asks it of
// every descriptor a waiter polls that the board does not own (docs/linux.md, Deadlocks): a pipe,
// or a socket pair, that no other process holds.
#pragma once

#include <string>

namespace l6470emu::preload {

/// What the /proc link at `path` names ("/proc/self/fd/3" -> "pipe:[123]" or a file's path), ""
/// when it cannot be read.
std::string link_of(const std::string& path);

/// Whether `fd` is a pipe that no other process holds an end of, in a process with no child
/// (whose end would be a SIGCHLD, and its handler may write the pipe). Read from /proc, which
/// takes a scan of every process: for a deadlock check, never on a hot path. Then nothing outside
/// this process can make it readable.
bool pipe_held_by_this_process_alone(int fd);

/// Whether `fd` is a connected AF_UNIX socket (a socketpair() end) whose peer, and itself, no
/// other process holds, in a process with no child: then nothing outside this process can send
/// to it. The peer is the kernel's answer (sock_diag's UNIX_DIAG_PEER, as `ss -x` asks); false
/// when it has none or the kernel cannot say. Reads /proc as pipe_held_by_this_process_alone.
bool socket_pair_held_by_this_process_alone(int fd);

}  // namespace l6470emu::preload
