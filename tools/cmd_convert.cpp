// `l6470emu convert TRACE -o OUT`: native text, VCD (with the emulated chain's pins and
// positions unless --no-emulation) or umockdev .ioctl.
#include <cmath>
#include <exception>
#include <memory>
#include <streambuf>
#include <string_view>
#include <ostream>

#include "daisychain/chain_spec.hpp"
#include "daisychain/emulated_vcd.hpp"
#include "spi/export_umockdev.hpp"
#include "spi/export_vcd.hpp"
#include "spi/trace_file.hpp"
#include "spi/trace_native.hpp"
#include "tools/progress.hpp"
#include "tools/trace_commands.hpp"

namespace l6470emu {
namespace {

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

/// An ostream's buffer over a TraceFileWriter (gzip when the name ends in .gz).
class FileBuf final : public std::streambuf {
 public:
  explicit FileBuf(const std::string& path) : file_(path) { setp(buf_, buf_ + sizeof buf_); }
  void close() {
    sync_out();
    file_.close();
  }

 protected:
  int_type overflow(int_type c) override {
    sync_out();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override {
    sync_out();
    return 0;
  }

 private:
  void sync_out() {
    file_.write(std::string_view(pbase(), static_cast<std::size_t>(pptr() - pbase())));
    setp(buf_, buf_ + sizeof buf_);
  }
  TraceFileWriter file_;
  char buf_[1 << 16];
};

}  // namespace

int run_convert(const ConvertArgs& args, std::ostream& out, std::ostream& err) {
  try {
    std::string to = args.to;
    const std::string_view name = without_gz(args.output);
    if (to == "auto") to = ends_with(name, ".vcd") ? "vcd" : ends_with(name, ".ioctl") ? "ioctl" : "native";
    const TraceFile file(args.trace.path, input_options(args.trace));
    print_notes(file.header(), err);

    std::unique_ptr<FileBuf> file_buf;
    std::ostream file_out(nullptr);
    std::ostream* dst = &out;
    if (args.output != "-") {
      file_buf = std::make_unique<FileBuf>(args.output);  // throws "OUT: cannot create: ..."
      file_out.rdbuf(file_buf.get());
      dst = &file_out;
    }
    if (to == "native") {
      NativeTraceWriter w(*dst, NativeWriteOptions{false, !args.expand});
      std::unique_ptr<TraceReader> reader = file.read();
      TraceHeader h = reader->header();
      if (!args.trace.chain.empty()) h.chain = chain_spec_of(parse_chain_spec(args.trace.chain));
      w.write_header(h);
      ProgressBar bar = ProgressBar::on_stderr("converting " + file.path());
      ProgressTraceReader watched(*reader, bar);
      TraceEvent e;
      while (watched.next(e)) w.write(e);
      bar.finish();
      w.finish();
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
    if (file_buf) file_buf->close();
    return kTraceOk;
  } catch (const std::exception& e) {
    err << "l6470emu convert: " << e.what() << "\n";
    return kTraceBadInput;
  }
}

}  // namespace l6470emu
