// CLI11 wiring of the trace subcommands and the options they share.
#include "tools/trace_commands.hpp"

#include <CLI/CLI.hpp>

#include "tools/cli_errors.hpp"

#include <csignal>
#include <iostream>
#include <memory>
#include <stdexcept>

namespace l6470emu {

TraceInputOptions input_options(const TraceArgs& args) {
  TraceInputOptions o;
  if (args.format != "auto") {
    o.format = trace_format_named(args.format);
    if (o.format == TraceFormat::unknown)
      throw std::invalid_argument("unknown format \"" + args.format +
                                  "\" (auto, native, saleae, umockdev, ftrace, sigrok, vcd)");
  }
  o.import.select = args.select;
  if (args.framing == "auto") o.import.ftrace_framing = FtraceFraming::automatic;
  else if (args.framing == "cs") o.import.ftrace_framing = FtraceFraming::cs;
  else if (args.framing == "transfer") o.import.ftrace_framing = FtraceFraming::transfer;
  else if (args.framing == "message") o.import.ftrace_framing = FtraceFraming::message;
  else throw std::invalid_argument("unknown framing \"" + args.framing + "\" (auto, cs, transfer, message)");
  if (!args.sigrok_decoder.empty()) o.sigrok_decoder = args.sigrok_decoder;
  o.import.max_frames = args.max_frames;
  return o;
}

TraceWorld world_of(const TraceArgs& args, const TraceFile& file) {
  return world_for_trace(WorldOptions{args.chain, args.board}, file);
}

NumberFrom number_from_option(const std::string& text) {
  try {
    return parse_number_from(text);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("--number-from: ") + e.what());
  }
}

void print_notes(const TraceHeader& header, std::ostream& err) {
  for (const std::string& n : header.notes) err << "note: " << header.name << ": " << n << "\n";
}

namespace {

/// A count given on the command line: decimal digits only (CLI11 would take "-1" as 2^64 - 1).
std::string count_option(const std::string& text) {
  if (text.empty() || text.size() > 19 || text.find_first_not_of("0123456789") != std::string::npos)
    return "'" + text.substr(0, 40) + "' is not a count (decimal digits, at most 19; 0 = no limit)";
  return {};
}

/// Ends the program with `status` when it is not 0 (CLI11 returns it from main quietly).
void finish(int status) {
  if (status != 0) throw CLI::RuntimeError(status);
}

}  // namespace

void add_trace_options(CLI::App* sub, TraceArgs& a) {
  sub->add_option("TRACE", a.path, "trace file: native, Saleae CSV, umockdev .ioctl, ftrace text, sigrok JSON, VCD or .sr")
      ->required();
  add_trace_reading_options(sub, a);
}

void add_trace_reading_options(CLI::App* sub, TraceArgs& a) {
  sub->add_option("--format", a.format, "input format (default: recognised from the content)")
      ->check(one_of({"auto", "native", "saleae", "umockdev", "ftrace", "sigrok", "vcd"}));
  sub->add_option("--chain", a.chain,
                  "the emulated chain, chip 0 (MISO end) first: N, N*VARIANT or a list (3, 2*L6470,L6480), or the "
                  "board description of one chain (\"chips=L6470 axis.0=stops=0..256000,switch=home@0\"); "
                  "default: the trace's own, else guessed from the frame lengths");
  sub->add_option("--board", a.board,
                  "a file with the board description of one chain (axes, switches, loads, numbering: "
                  "docs/linux.md) to run a capture through; replaces the trace's own, which the output says");
  sub->add_option("--select", a.select,
                  "the stream to take when the file has several: Saleae analyzer name, ftrace device (spi0.0), "
                  "sigrok decoder (spi-1)");
  sub->add_option("--framing", a.framing, "ftrace CS frames: auto, cs (spi_set_cs), transfer, message")
      ->check(one_of({"auto", "cs", "transfer", "message"}));
  sub->add_option("--sigrok-decoder", a.sigrok_decoder,
                  "sigrok-cli decoder for VCD/.sr captures (default spi:clk=SCK:mosi=MOSI:miso=MISO:cs=CS:cpol=1:cpha=1)");
  sub->add_option("--max-frames", a.max_frames,
                  "the most frames the trace may hold, 'repeat' lines counted as the frames they stand for (default " +
                      std::to_string(kDefaultMaxTraceFrames) + "; 0 = no limit): a trace asking for more is refused at once")
      ->check(count_option);
}

void add_number_from_option(CLI::App* sub, std::string& value) {
  sub->add_option("--number-from", value,
                  "which end chip 0 is at: miso (chip 0 drives MISO, the default) or mosi (chip 0 reads the host's MOSI)");
}

void add_trace_commands(CLI::App& app) {
  auto replay = std::make_shared<ReplayArgs>();
  CLI::App* r = app.add_subcommand(
      "replay", "drive a captured trace's MOSI into the emulated chain and compare every MISO byte "
                "(exit 0 = matched, 1 = diverged, 2 = bad input)");
  add_trace_options(r, replay->trace);
  r->add_flag("--continue", replay->keep_going, "report every divergence, not only the first");
  r->add_option("--max-reports", replay->max_reports, "with --continue: full reports for this many (0 = all)");
  r->add_flag("--no-pins", replay->no_pins, "do not compare the trace's pin observations (BUSY, FLAG, SW the axis drove)");
  r->add_flag("--quiet", replay->quiet, "one line per divergence instead of the full report");
  add_number_from_option(r, replay->number_from);
  r->callback([replay] { finish(run_replay(*replay, std::cout, std::cerr)); });

  auto decode = std::make_shared<DecodeArgs>();
  CLI::App* d = app.add_subcommand("decode", "explain a trace: every command and answer per chip, with protocol diagnostics "
                                             "(exit 0; 1 = the emulator does not reproduce the trace; 2 = bad input)");
  add_trace_options(d, decode->trace);
  d->add_flag("--nops", decode->nops, "also list NOPs and STCK edges");
  d->add_flag("--accept-divergence", decode->accept_divergence,
              "exit 0 even when the emulator does not reproduce the trace (the log still marks where it parts)");
  d->add_option("--max-repeats", decode->max_repeats, "show each kind of diagnostic at most this often per chip (0 = all)");
  d->add_option("--chip", decode->chip, "show only this chip's lines (numbered as --number-from says)")
      ->check(CLI::Range(0, 255));
  add_number_from_option(d, decode->number_from);
  d->callback([decode] { finish(run_decode(*decode, std::cout, std::cerr)); });

  auto convert = std::make_shared<ConvertArgs>();
  CLI::App* c = app.add_subcommand(
      "convert", "write a trace as native text, VCD (SPI wires in mode 3, BUSY/FLAG/SW/STCK/STBY, ABS_POS) or umockdev .ioctl");
  add_trace_options(c, convert->trace);
  c->add_option("-o,--output", convert->output, "file to write (- = standard output; a name ending in .gz is gzip-compressed)")
      ->required();
  c->add_option("--to", convert->to, "output format (default: from the extension before any .gz: .vcd, .ioctl, else native)")
      ->check(one_of({"auto", "native", "vcd", "ioctl"}));
  c->add_option("--device", convert->device, "umockdev: the spidev node the recording is for");
  c->add_option("--timescale-ns", convert->timescale_ns, "VCD time unit in ns (1, 10 or 100)")
      ->check(CLI::IsMember({1u, 10u, 100u}));
  c->add_option("--sample-us", convert->sample_us, "VCD: how often moving chips are looked at, in µs")
      ->check(CLI::Range(0.25, 1e6));
  c->add_flag("--no-emulation", convert->no_emulation, "VCD: only the trace's own signals, no emulated BUSY/FLAG/ABS_POS");
  c->add_flag("--expand", convert->expand,
              "native: one line per frame (by default frames repeated at a constant period become 'repeat' lines)");
  c->add_option("--max-output", convert->max_output,
                "the most bytes the output may take, before compression (default 1G; K, M, G, T are powers of 1024; "
                "0 = no limit): a conversion that would write more is refused before it starts");
  c->callback([convert] {
    // A reader that goes away (`convert -o - | head`) is a write error with a message and
    // exit status 2, not a silent death by SIGPIPE.
    std::signal(SIGPIPE, SIG_IGN);
    finish(run_convert(*convert, std::cout, std::cerr));
  });
}

}  // namespace l6470emu
