// The trace subcommands of l6470emu: replay (compare a capture with the emulator),
// decode (explain it), convert (native, VCD or umockdev .ioctl out). Each is a function
// with its exit status, so tests run them without a process; add_trace_commands wires
// them into the CLI11 program.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>

#include "daisychain/chip_numbering.hpp"
#include "tools/trace_input.hpp"
#include "tools/trace_world.hpp"

namespace CLI {
class App;
}

namespace l6470emu {

/// Options every trace subcommand takes.
struct TraceArgs {
  std::string path;            ///< the trace file
  std::string format = "auto";  ///< auto, native, saleae, umockdev, ftrace, sigrok, vcd
  std::string chain;           ///< chain ("3", "2*L6470,L6480") or board description of one chain; empty = the trace's own
  std::string board;           ///< --board: a file with the board description of one chain; empty = the trace's own
  std::string select;          ///< analyzer / device / decoder to take when the file has several
  std::string framing = "auto";  ///< ftrace: auto, cs, transfer, message
  std::string sigrok_decoder;  ///< sigrok-cli decoder spec for VCD/.sr captures (empty = the default)
  std::uint64_t max_frames = kDefaultMaxTraceFrames;  ///< the most frames the trace may hold (0: no limit)
};

/// The reading options `args` stand for. Throws std::invalid_argument for an unknown
/// format or framing name.
TraceInputOptions input_options(const TraceArgs& args);

/// The world `args` ask for (--chain, --board) for `file`, or the trace's own.
TraceWorld world_of(const TraceArgs& args, const TraceFile& file);

/// The value of a --number-from option ("miso" or "mosi"). Throws std::invalid_argument
/// with one line starting "--number-from: " for anything else.
NumberFrom number_from_option(const std::string& text);

/// Prints the importer's notes about `header` to `err`, one "note:" line each.
void print_notes(const TraceHeader& header, std::ostream& err);

/// Exit statuses of the trace subcommands.
enum TraceExit : int { kTraceOk = 0, kTraceDiverged = 1, kTraceBadInput = 2 };

struct ReplayArgs {
  TraceArgs trace;
  bool keep_going = false;    ///< --continue
  std::size_t max_reports = 100;
  bool no_pins = false;       ///< do not check BUSY/FLAG observations
  bool quiet = false;         ///< summary line only
  std::string number_from = "miso";  ///< how reports number the chips: miso or mosi
};
/// `l6470emu replay`: 0 when every captured MISO byte and pin level matched, 1 when not, 2 on bad input.
int run_replay(const ReplayArgs& args, std::ostream& out, std::ostream& err);

struct DecodeArgs {
  TraceArgs trace;
  bool accept_divergence = false;  ///< exit 0 even when the emulator does not reproduce the trace
  bool nops = false;
  std::size_t max_repeats = 10;
  int chip = -1;  ///< only this chip's lines (numbered as number_from says)
  std::string number_from = "miso";  ///< how the log numbers the chips: miso or mosi
};
/// `l6470emu decode`: 0; 1 when the emulator does not reproduce the trace (the log then marks
/// where, and what follows is the emulator's model) unless accept_divergence; 2 on bad input.
int run_decode(const DecodeArgs& args, std::ostream& out, std::ostream& err);

struct ConvertArgs {
  TraceArgs trace;
  std::string output;           ///< file to write ("-" = standard output)
  std::string to = "auto";      ///< native, vcd, ioctl; auto = from the output's extension
  std::string device = "/dev/spidev0.0";  ///< umockdev device name
  unsigned timescale_ns = 10;   ///< VCD time unit
  double sample_us = 10;        ///< VCD: how often moving chips are looked at
  bool no_emulation = false;    ///< VCD: only what the trace holds (no BUSY/FLAG/ABS_POS from the emulator)
  bool expand = false;          ///< native: one line per frame, no `repeat` lines
  /// The most bytes the output may take (uncompressed), as --max-output takes it ("1G", "500M",
  /// "0" = no limit): a conversion that would write more is refused before it starts.
  std::string max_output = "1G";
};
/// `l6470emu convert`: 0, or 2 on bad input.
int run_convert(const ConvertArgs& args, std::ostream& out, std::ostream& err);

/// Adds the options every trace subcommand takes (TRACE, --format, --chain, --board, --select,
/// --framing, --sigrok-decoder, --max-frames) to `sub`, into `a`.
void add_trace_options(CLI::App* sub, TraceArgs& a);
/// The same without TRACE (a subcommand that takes its traces its own way, as `report`).
void add_trace_reading_options(CLI::App* sub, TraceArgs& a);
/// Adds --number-from to `sub`, into `value`.
void add_number_from_option(CLI::App* sub, std::string& value);

/// Adds replay, decode and convert to `app`. They run in CLI11 callbacks and end the
/// program through CLI::RuntimeError with their exit status when it is not 0.
void add_trace_commands(CLI::App& app);

}  // namespace l6470emu
