// Text from a source that is not trusted (a daemon's reply, a path), made safe to print on a
// terminal. Not a general escaping scheme: what it writes is for people to read.
#pragma once

#include <string>
#include <string_view>

namespace l6470emu {

/// `text` as it may be printed on a terminal: newlines and tabs kept, valid UTF-8 kept, every
/// other control character (C0, DEL, C1 such as the escape sequences' ESC and CSI) and every byte
/// that is not part of valid UTF-8 written as \xNN, so no escape sequence reaches the terminal.
std::string terminal_safe(std::string_view text);

}  // namespace l6470emu
