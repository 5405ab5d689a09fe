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
#include "tools/trace_world.hpp"

namespace l6470emu::python {

/// A format= argument: None or "auto" = recognise it; else a format name (ValueError otherwise).
TraceFormat format_arg(const py::object& format);

/// A trace to read and the world (the chain's board description) to read it through.
struct Source {
  std::shared_ptr<const Trace> trace;   ///< a Trace object
  std::unique_ptr<TraceFile> file;      ///< or a file (native ones are streamed)
  TraceWorld world;                     ///< the chain, its axes and the rest of its description; .how says whence

  /// A fresh pass over the events.
  std::unique_ptr<TraceReader> reader() const { return trace ? trace->reader() : file->read(); }
  /// Number of chips.
  std::size_t chips() const { return world.chain().chips.size(); }
};

/// A max_frames= argument: the most frames a trace file may hold, 0 for no limit (ValueError
/// when negative, TypeError when not an int).
std::uint64_t max_frames_arg(py::handle max_frames);

/// `trace` (a Trace or a path) with `chain` (None: the trace's own; variants, or a board
/// description of one chain as a str with '='), `board` (None, or the path of a file holding
/// such a description), `format` and, for files holding several streams, `select`; a file may
/// hold at most `max_frames` frames (0: no limit). Raises ValueError for a trace without a chain
/// or a bad chain, TraceError for a file that cannot be read or holds too many frames, or a bad
/// board file.
Source source_of(py::handle trace, py::handle chain, py::handle format, const std::string& select = "",
                 std::uint64_t max_frames = kDefaultMaxTraceFrames, py::handle board = py::none());

}  // namespace l6470emu::python
