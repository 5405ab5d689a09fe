// Reading a board description from a file (L6470EMU_CONFIG, `serve --config`) with the OS's
// own calls, so that a directory, a device or an endless FIFO fails fast with one line.
#pragma once

#include <string>

#include "board/board_config.hpp"

namespace l6470emu {

/// Reads the file (at most kMaxConfigBytes + 1 bytes: /dev/zero or an endless FIFO fails fast)
/// and parses it. A directory, a device or an unreadable file is a ConfigError saying so.
ParseResult load_board_config_file(const std::string& path);

}  // namespace l6470emu
