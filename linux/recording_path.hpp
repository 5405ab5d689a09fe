// Which paths the Linux front records into: a regular file only, never through a symbolic link,
// and nothing whose opening could block (a daemon, root perhaps, holds its board's lock while it
// opens one). The recording itself is spi/recording_output.hpp's.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "spi/recording_output.hpp"

namespace l6470emu {

/// Throws std::runtime_error (one line) unless `path` is a regular file or can be created as one:
/// a symbolic link, a FIFO, a device or a directory is refused, and a missing file is created
/// (O_EXCL, not following a link planted meanwhile).
void check_recording_path(const std::string& path);

/// The output of a recording from the Linux front: check_recording_path, then
/// open_recording_output with `clock` (host monotonic ns) for the gzip flush points.
std::unique_ptr<TraceOutput> open_host_recording_output(const std::string& path, std::function<std::int64_t()> clock);

}  // namespace l6470emu
