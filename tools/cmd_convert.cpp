// `l6470emu convert TRACE -o OUT`: native text, VCD (with the emulated chain's pins and
// positions unless --no-emulation) or umockdev .ioctl.
#include <cmath>
#include <exception>
#include <fstream>
#include <ostream>

#include "daisychain/chain_spec.hpp"
#include "daisychain/emulated_vcd.hpp"
#include "spi/export_umockdev.hpp"
#include "spi/export_vcd.hpp"
#include "spi/trace_native.hpp"
#include "tools/trace_commands.hpp"

namespace l6470emu {
namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

int run_convert(const ConvertArgs& args, std::ostream& out, std::ostream& err) {
  try {
    std::string to = args.to;
    if (to == "auto") to = ends_with(args.output, ".vcd") ? "vcd" : ends_with(args.output, ".ioctl") ? "ioctl" : "native";
    const TraceFile file(args.trace.path, input_options(args.trace));
    print_notes(file.header(), err);

    std::ofstream file_out;
    std::ostream* dst = &out;
    if (args.output != "-") {
      file_out.open(args.output, std::ios::binary | std::ios::trunc);
      if (!file_out) throw std::runtime_error(args.output + ": cannot create");
      dst = &file_out;
    }
    if (to == "native") {
      NativeTraceWriter w(*dst, false);
      std::unique_ptr<TraceReader> reader = file.read();
      TraceHeader h = reader->header();
      if (!args.trace.chain.empty()) h.chain = chain_spec_of(parse_chain_spec(args.trace.chain));
      w.write_header(h);
      TraceEvent e;
      while (reader->next(e)) w.write(e);
    } else if (to == "ioctl") {
      std::unique_ptr<TraceReader> reader = file.read();
      const UmockdevExportStats s = export_umockdev_ioctl(*reader, *dst, args.device);
      if (s.frames_without_miso)
        err << "note: " << s.frames_without_miso << " frames without a complete MISO: written without R (don't care)\n";
    } else {
      const Trace trace = file.load();
      if (args.no_emulation) {
        export_vcd(trace, *dst, {args.timescale_ns});
      } else {
        std::string how;
        Chain chain = make_chain(chain_for_trace(args.trace.chain, file, how));
        EmulatedVcdOptions o;
        o.timescale_ns = args.timescale_ns;
        o.sample_ticks = static_cast<Tick>(std::llround(args.sample_us * kTicksPerMicrosecond));
        export_emulated_vcd(trace, chain, *dst, o);
        err << "l6470emu: BUSY, FLAG and ABS_POS from an emulated chain " << chain_spec_of(chain) << " (" << how << ")\n";
      }
    }
    dst->flush();
    if (!*dst) throw std::runtime_error(args.output + ": write failed");
    return kTraceOk;
  } catch (const std::exception& e) {
    err << "l6470emu convert: " << e.what() << "\n";
    return kTraceBadInput;
  }
}

}  // namespace l6470emu
