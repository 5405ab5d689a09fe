// Opening a file the user names as input (a trace, a board description, a scenario) so that it
// can never block for ever: a regular file opens as it is; a FIFO (a shell's <(...)) once its
// writer has written something or gone, waiting a bounded time; a directory, a device (/dev/zero
// never ends, a terminal waits for a person) or a socket is refused with the reason.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

namespace l6470emu {

/// How long open_input_file waits for a FIFO's writer by default: 10 s.
inline constexpr int kInputFifoWaitMs = 10'000;

/// Opens `path` for reading (blocking reads, close-on-exec). Returns the descriptor, or -1 with
/// `error` set to what is wrong, without the path: "cannot be read (No such file or directory)",
/// "is a directory", "is a device, not a file: it could block or never end", "is a socket, not a
/// file", "is a FIFO that nothing wrote to within 10 s". errno is then the system's error when
/// the file could not be opened at all, 0 when what the file is was refused.
int open_input_file(const std::string& path, std::string& error, int fifo_wait_ms = kInputFifoWaitMs);

/// Opens `path` as open_input_file does and reads at most `max_bytes` + 1 bytes of it, so that
/// the caller can tell a file longer than `max_bytes`. The text, or nothing with `error` set.
std::optional<std::string> read_input_file(const std::string& path, std::size_t max_bytes, std::string& error);

}  // namespace l6470emu
