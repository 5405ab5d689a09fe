// Where a board's recordings go, from every front: a plain trace file written through a
// MAP_SHARED mapping (appending a line and updating a `repeat` count are memory writes, not system
// calls, and the pages belong to the file, so a killed process leaves every event written), and
// gzip files flushed by size and, when the front has one, host time. It neither formats traces
// (spi/trace_native.hpp does) nor judges which paths a front may write (linux/recording_path.hpp).
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "spi/trace_output.hpp"

namespace l6470emu {

/// How often a gzip recording hands its compressed data to the OS: every 64 KiB of text or
/// 200 ms of host time after the last flush, whichever comes first (while a run of repeated
/// frames is all that is new, ever further apart: TraceFlushPolicy::gzip_quiet_interval_ns).
inline constexpr std::size_t kRecordingGzipFlushBytes = 64 * 1024;
inline constexpr std::int64_t kRecordingGzipFlushNs = 200'000'000;

/// A plain trace file at `path` (created or truncated) written through a shared mapping. The
/// file grows in chunks (the space is reserved with fallocate, so a full disk is an error here,
/// never a SIGBUS later); while it is being written its length is the chunk's and the unwritten
/// rest is zero bytes, where readers stop; close() cuts it to the trace's length. Every append
/// becomes visible in one store (its first byte, written last), and replace_tail of a `repeat`
/// count in one aligned 8-byte store, so a process killed at any instant leaves a trace whose
/// every line is whole. Returns nullptr when `path` is not a regular file (a FIFO, /dev/stdout:
/// the caller writes it the ordinary way); throws std::runtime_error (one line) when it cannot
/// be created or mapped.
std::unique_ptr<TraceOutput> open_mapped_trace_output(const std::string& path);

/// The output of a recording at `path` (what Board::start_recording opens unless its front says
/// otherwise): mapped (open_mapped_trace_output) for a plain file; for a name ending in ".gz",
/// zlib flushed every kRecordingGzipFlushBytes of text or, when `clock` (host monotonic ns) is
/// given, kRecordingGzipFlushNs after the last flush; stdio for what cannot be mapped (a FIFO,
/// /dev/stdout). Without a clock (a firmware program in virtual time) the flush points, and so the
/// text, depend on the events alone. Throws std::runtime_error (one line) when `path` cannot be
/// created.
std::unique_ptr<TraceOutput> open_recording_output(const std::string& path, std::function<std::int64_t()> clock = {});

}  // namespace l6470emu
