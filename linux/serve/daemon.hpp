// `l6470emu serve`: owns a DeviceBoard and serves host programs (through the preload library)
// and `ctl` over one Unix SOCK_SEQPACKET socket, a thread per connection.
#pragma once

#include <functional>
#include <memory>
#include <ostream>
#include <string>

#include "board/board_config.hpp"

namespace l6470emu {

/// The socket path used when none is given: $L6470EMU_SOCKET, else $XDG_RUNTIME_DIR/l6470emu.sock,
/// else /tmp/l6470emu-<uid>.sock.
std::string default_socket_path();

class DeviceBoard;

/// More ways in, started once the board exists (the kernel nodes of `serve --cuse --uhid`):
/// returns what must stay alive while the daemon serves, or sets `error` to one line. Whatever
/// it prints to `out` goes before the daemon's "run programs with" line.
using FrontEnds = std::function<std::shared_ptr<void>(DeviceBoard& board, std::ostream& out, std::string& error)>;

/// Serves `config` on `socket_path` until SIGINT or SIGTERM. Prints one line when ready, naming
/// `preload_library` as the LD_PRELOAD to use ("<path>/libl6470emu-preload.so" when empty).
/// Returns the exit status (non-zero when the socket or a front end cannot be set up).
int run_daemon(const BoardConfig& config, const std::string& socket_path, std::ostream& out, std::ostream& err,
               const FrontEnds& front_ends = {}, const std::string& preload_library = {});

/// Sends one control command to the daemon at `socket_path`; prints its answer.
int run_ctl(const std::string& socket_path, const std::string& command, std::ostream& out, std::ostream& err);

}  // namespace l6470emu
