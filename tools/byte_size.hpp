// Sizes in bytes on the command line: "500M", "10G", "1.5GiB" read, and written back for
// messages ("1.0 GiB"). Binary units throughout (K = 1024 bytes), as `ls -h` and `du -h` show them.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace l6470emu {

/// `text` as a number of bytes: digits with an optional fraction, then nothing (bytes) or K, M,
/// G, T (binary: KiB, MiB, GiB, TiB are the same; a trailing B or iB and any case accepted).
/// Nothing for anything else, or more than 2^64 - 1 bytes.
std::optional<std::uint64_t> parse_byte_size(std::string_view text);

/// `bytes` for people: "512 bytes", "1.5 KiB", "214.0 GiB" (one decimal from KiB up).
std::string format_byte_size(std::uint64_t bytes);

}  // namespace l6470emu
