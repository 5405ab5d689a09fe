// Where replay(), decode() and motion() read a trace from: a Trace object or a file in any
// format the l6470emu program reads, and the chain it runs through (given, the trace's own, or
// guessed from a file's frame lengths).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "spi/trace.hpp"
#include "tools/trace_input.hpp"

namespace l6470emu::python {

/// A format= argument: None or "auto" = recognise it; else a format name (ValueError otherwise).
TraceFormat format_arg(const py::object& format);

/// A trace to read and the chain to read it through.
struct Source {
  std::shared_ptr<const Trace> trace;   ///< a Trace object
  std::unique_ptr<TraceFile> file;      ///< or a file (native ones are streamed)
  std::vector<const Variant*> variants;
  std::string how;                      ///< where the chain came from, in words

  /// A fresh pass over the events.
  std::unique_ptr<TraceReader> reader() const { return trace ? trace->reader() : file->read(); }
};

/// A max_frames= argument: the most frames a trace file may hold, 0 for no limit (ValueError
/// when negative, TypeError when not an int).
std::uint64_t max_frames_arg(py::handle max_frames);

/// `trace` (a Trace or a path) with `chain` (None: the trace's own), `format` and, for files
/// holding several streams, `select`; a file may hold at most `max_frames` frames (0: no limit).
/// Raises ValueError for a trace without a chain or a bad chain, TraceError for a file that
/// cannot be read or holds too many frames.
Source source_of(py::handle trace, py::handle chain, py::handle format, const std::string& select = "",
                 std::uint64_t max_frames = kDefaultMaxTraceFrames);

}  // namespace l6470emu::python
