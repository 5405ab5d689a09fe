// Opening a trace file for the command line: recognising its format, streaming native
// traces, importing the others, running sigrok-cli on logic captures (VCD, .sr), and
// choosing the chain to run it through. No replay or decode logic here.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/variant.hpp"
#include "spi/trace.hpp"
#include "spi/trace_import.hpp"

namespace l6470emu {

/// How to read a trace file.
struct TraceInputOptions {
  TraceFormat format = TraceFormat::unknown;  ///< unknown = recognise from the content
  ImportOptions import;
  /// sigrok-cli's spi decoder with its channel names, for VCD and .sr captures (mode 3).
  std::string sigrok_decoder = "spi:clk=SCK:mosi=MOSI:miso=MISO:cs=CS:cpol=1:cpha=1";
  std::string sigrok_cli = "sigrok-cli";  ///< the program to run
  /// How long sigrok-cli may take before it is stopped; 0 = by the file's size (1 s per 100 kB, at least 30 s).
  std::chrono::seconds sigrok_time_limit{0};
};

/// A trace file, opened: native traces are streamed from disk on every pass (any length),
/// other formats are imported into memory once (read from the file a piece at a time). Either
/// way a trace hands out at most options.import.max_frames frames. Throws TraceError (cannot
/// open, unknown format, malformed input, too many frames) from the constructor and from the
/// readers.
class TraceFile {
 public:
  TraceFile(std::string path, const TraceInputOptions& options);

  const std::string& path() const { return path_; }
  TraceFormat format() const { return format_; }
  /// The header (native: as read from the file's first lines).
  const TraceHeader& header() const { return header_; }
  /// A new pass over the events, from the first.
  std::unique_ptr<TraceReader> read() const;
  /// The whole trace in memory (a native file is read in now).
  Trace load() const;

 private:
  void open(const TraceInputOptions& options);
  std::string out_of_memory() const;

  std::string path_;
  TraceFormat format_;
  std::uint64_t max_frames_;
  TraceHeader header_;
  Trace trace_;  // non-native formats
};

/// Runs sigrok-cli's spi decoder over a logic capture (VCD or .sr) and returns its JSON
/// trace. Throws TraceError when sigrok-cli is missing, fails (with its message) or takes
/// longer than the time limit (it is killed then). sigrok-cli is killed too if this process dies.
std::string run_sigrok_spi_decoder(const std::string& path, const TraceInputOptions& options);

/// The chain a trace runs through: `spec` when given, else the trace's own chain line, else
/// as many L6470s as its most common frame length (from its first 10000 frames). `how` says
/// which, in words. Throws TraceError for a malformed chain description.
std::vector<const Variant*> chain_for_trace(const std::string& spec, const TraceFile& file, std::string& how);

}  // namespace l6470emu
