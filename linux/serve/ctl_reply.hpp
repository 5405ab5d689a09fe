// What `l6470emu ctl` makes of the daemon's reply: the text it prints (made safe for a terminal)
// and its exit status. Not here: sending the command (serve/daemon.cpp run_ctl).
#pragma once

#include <cstdint>
#include <span>
#include <string>

namespace l6470emu {

/// What ctl prints and returns for one reply packet.
struct CtlOutcome {
  int status = 1;          ///< 0 done, 1 failed (also: anything the daemon should not have said), 2 usage
  std::string text;        ///< what to print: terminal-safe, ends with a newline unless empty
  bool on_stderr = false;  ///< print it on stderr (every status but 0)
};

/// Decodes the daemon's reply to a control request (a ReplyHeader and text). The daemon is
/// trusted only as far as the owner check goes, and a bug should not mislead either: the exit
/// status is the reply's only when it is 0, 1 or 2 (else 1, with a line saying what came), a
/// refusal or a truncated reply gives 1 and a line naming `socket_path`, and the text goes
/// through terminal_safe() (linux/terminal_text.hpp).
CtlOutcome decode_ctl_reply(std::span<const std::uint8_t> reply, const std::string& socket_path);

}  // namespace l6470emu
