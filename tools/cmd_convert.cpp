// `l6470emu convert TRACE -o OUT`: native text, VCD (with the emulated chain's pins and
// positions unless --no-emulation) or umockdev .ioctl, streamed (memory does not grow with the
// trace), refused up front when the output would pass --max-output.
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <iostream>
#include <memory>
#include <streambuf>
#include <optional>
#include <ostream>
#include <string_view>
#include <vector>

#include "daisychain/chain_spec.hpp"
#include "core/counted.hpp"
#include "daisychain/emulated_vcd.hpp"
#include "spi/export_size.hpp"
#include "spi/export_umockdev.hpp"
#include "spi/export_vcd.hpp"
#include "spi/trace_file.hpp"
#include "spi/trace_native.hpp"
#include "tools/byte_size.hpp"
#include "tools/output_check.hpp"
#include "tools/progress.hpp"
#include "tools/trace_commands.hpp"

namespace l6470emu {
namespace {

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

/// The message for an output stopped at the output limit (what its size could not be told from
/// the trace's counts: an emulated chain's samples while the motors move).
std::string stopped_at_limit(const std::string& where, std::uint64_t limit) {
  return where + ": stopped at " + format_byte_size(limit) +
         ", the output limit: what was written is incomplete (raise it with --max-output SIZE; 0 = no limit)";
}

/// An ostream's buffer that hands each buffer-full to write_out() and keeps the first write
/// error with its text ("out.vcd: write failed: No space left on device"): a stream swallows
/// what its buffer throws, and std::cout loses errno. After an error the stream goes bad.
/// It writes at most `limit` bytes (0 = no limit): the next one is an error too.
class ErrorKeepingBuf : public std::streambuf {
 public:
  ErrorKeepingBuf(std::string where, std::uint64_t limit) : where_(std::move(where)), limit_(limit) {
    setp(buf_, buf_ + sizeof buf_);
  }
  /// The first write error, or "".
  const std::string& error() const { return error_; }

 protected:
  /// Writes `bytes` out; returns "" or the error's text.
  virtual std::string write_out(std::string_view bytes) = 0;
  /// Writes what is buffered (nothing after an error); false once an error happened.
  bool sync_out() {
    if (!error_.empty()) return false;
    std::string_view pending(pbase(), static_cast<std::size_t>(pptr() - pbase()));
    const bool over = limit_ != 0 && pending.size() > limit_ - written_;
    if (over) pending = pending.substr(0, static_cast<std::size_t>(limit_ - written_));
    error_ = write_out(pending);
    written_ += pending.size();
    if (error_.empty() && over) error_ = stopped_at_limit(where_, limit_);
    if (!error_.empty()) return false;
    setp(buf_, buf_ + sizeof buf_);
    return true;
  }
  int_type overflow(int_type c) override {
    if (!sync_out()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return sync_out() ? 0 : -1; }

 private:
  std::string error_;
  std::string where_;
  std::uint64_t limit_;
  std::uint64_t written_ = 0;
  char buf_[1 << 16];
};

/// Over a TraceFileWriter (gzip when the name ends in .gz).
class FileBuf final : public ErrorKeepingBuf {
 public:
  FileBuf(const std::string& path, std::uint64_t limit) : ErrorKeepingBuf(path, limit), file_(path) {}
  /// Keeps what was written before an error elsewhere (the file is then finished by file_).
  ~FileBuf() override { sync_out(); }
  /// Writes what is buffered and finishes the file; throws the first write error.
  void close() {
    if (!sync_out()) throw std::runtime_error(error());
    file_.close();
  }

 private:
  std::string write_out(std::string_view bytes) override {
    try {
      file_.write(bytes);
    } catch (const std::exception& e) {
      return e.what();
    }
    return {};
  }
  TraceFileWriter file_;
};

/// Over standard output's descriptor, so that a write error keeps its reason
/// ("standard output: write failed: Broken pipe").
class StdoutBuf final : public ErrorKeepingBuf {
 public:
  explicit StdoutBuf(std::uint64_t limit) : ErrorKeepingBuf("standard output", limit) {}
  /// Keeps what was written before an error elsewhere.
  ~StdoutBuf() override { sync_out(); }
  /// Writes what is buffered; throws the first write error.
  void close() {
    if (!sync_out()) throw std::runtime_error(error());
  }

 private:
  std::string write_out(std::string_view bytes) override {
    const char* p = bytes.data();
    const char* const end = p + bytes.size();
    while (p < end) {
      const ssize_t n = ::write(STDOUT_FILENO, p, static_cast<std::size_t>(end - p));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return std::string("standard output: write failed: ") + std::strerror(n < 0 ? errno : EIO);
      p += n;
    }
    return {};
  }
};

/// Where the output goes, for messages: "standard output" or the path as given.
std::string output_name(const std::string& output) { return output == "-" ? "standard output" : output; }

/// What --max-output takes (its default, 1G, and why: docs/trace-format.md, "Exporters").
constexpr std::string_view kMaxOutputWords = "a size: bytes, or a number with K, M, G or T (500M, 10G); 0 = no limit";

/// --max-output's value in bytes (0 = no limit); throws std::invalid_argument for anything else.
std::uint64_t max_output_bytes(const std::string& text) {
  const std::optional<std::uint64_t> bytes = parse_byte_size(text);
  if (!bytes) throw std::invalid_argument("--max-output: '" + text + "' is not " + std::string(kMaxOutputWords));
  return *bytes;
}

/// Refuses, with one line, an output that would be a regular file over one of the inputs, a
/// read-only file or in a folder that does not exist. A device or a pipe (/dev/null, /dev/full,
/// a FIFO) is written as a stream and never is a trace file: it is not checked.
void check_output(const std::string& output, const std::vector<std::string>& inputs) {
  struct stat st {};
  if (::stat(output.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) return;
  if (const std::string why = output_problem(output, inputs); !why.empty())
    throw std::runtime_error("cannot write " + output + ": " + why);
}

/// What the output format is called in messages.
std::string_view format_words(ExportFormat f) {
  switch (f) {
    case ExportFormat::native: return "native text";
    case ExportFormat::native_expanded: return "expanded native text";
    case ExportFormat::umockdev_ioctl: return "umockdev .ioctl";
    case ExportFormat::vcd: return "VCD";
  }
  return "";
}

/// `bytes` as a --max-output value that holds it, rounded up to whole MiB or GiB ("236G").
std::string enough_for(std::uint64_t bytes) {
  constexpr std::uint64_t kGiB = std::uint64_t{1} << 30, kMiB = std::uint64_t{1} << 20;
  if (bytes >= kGiB) return std::to_string(bytes / kGiB + (bytes % kGiB != 0)) + "G";
  return std::to_string(bytes / kMiB + 1) + "M";
}

/// Reads `file` once, counting what converting it to `format` writes, and throws one line when
/// it is more than `limit` bytes: refused before anything is written. A malformed line stops
/// the count: the conversion then meets it where it is, after writing what comes before it.
void refuse_if_too_large(const TraceFile& file, ExportFormat format, unsigned timescale_ns, std::uint64_t limit,
                         const std::string& where) {
  ExportSizeCounter size(format, timescale_ns);
  try {
    std::unique_ptr<TraceReader> reader = file.read();
    ProgressBar bar = ProgressBar::on_stderr("sizing " + file.path());
    ProgressTraceReader watched(*reader, bar);
    TraceEvent e;
    while (watched.next(e)) size.add(e);
    bar.finish();
  } catch (const TraceError&) {
  }
  if (size.bytes() <= limit) return;
  throw std::runtime_error(where + ": " + std::string(format_words(format)) + " of " + counted(size.frames(), "frame") +
                           " (" + format_byte_size(size.frame_bytes()) + " of MOSI) would take " +
                           (format == ExportFormat::vcd ? "at least " : "") + format_byte_size(size.bytes()) +
                           ", more than " + format_byte_size(limit) +
                           ", the output limit (raise it with --max-output " + enough_for(size.bytes()) +
                           "; 0 = no limit)");
}

}  // namespace

int run_convert(const ConvertArgs& args, std::ostream& out, std::ostream& err) {
  try {
    std::string to = args.to;
    const std::string_view name = without_gz(args.output);
    if (to == "auto") to = ends_with(name, ".vcd") ? "vcd" : ends_with(name, ".ioctl") ? "ioctl" : "native";
    const std::uint64_t max_output = max_output_bytes(args.max_output);
    const TraceFile file(args.trace.path, input_options(args.trace));
    print_notes(file.header(), err);

    const std::string where = output_name(args.output);
    if (args.output != "-") check_output(args.output, {args.trace.path, args.trace.board});
    const ExportFormat format = to == "vcd"     ? ExportFormat::vcd
                                : to == "ioctl" ? ExportFormat::umockdev_ioctl
                                : args.expand   ? ExportFormat::native_expanded
                                                : ExportFormat::native;
    if (max_output != 0) refuse_if_too_large(file, format, args.timescale_ns, max_output, where);
    // The program's standard output is written through its descriptor, so that a write error
    // has its reason; a test's stream as it is.
    std::unique_ptr<StdoutBuf> stdout_buf;
    std::ostream stdout_stream(nullptr);
    std::ostream* to_stdout = &out;
    if (args.output == "-" && out.rdbuf() == std::cout.rdbuf()) {
      std::cout.flush();
      stdout_buf = std::make_unique<StdoutBuf>(max_output);
      stdout_stream.rdbuf(stdout_buf.get());
      to_stdout = &stdout_stream;
    }
    if (to == "native") {
      // A file is written by the writer itself (its errors name the file), standard output
      // through the stream (its errors say "standard output").
      std::unique_ptr<TraceReader> reader = file.read();
      const NativeWriteOptions wo{false, !args.expand};
      std::unique_ptr<NativeTraceWriter> writer = args.output == "-"
                                                      ? std::make_unique<NativeTraceWriter>(*to_stdout, wo, where)
                                                      : std::make_unique<NativeTraceWriter>(args.output, wo);
      NativeTraceWriter& w = *writer;
      TraceHeader h = reader->header();
      if (!args.trace.chain.empty() || !args.trace.board.empty()) {
        // The world given goes into the header: a capture keeps the board it was given.
        const TraceWorld world = world_of(args.trace, file);
        h.chain = chain_spec_of(world.chain().chips);
        h.board = args.trace.board.empty() && args.trace.chain.find('=') == std::string::npos ? "" : world.board_text();
        if (world.overrides) err << "note: " << world.override_note(file.path()) << "\n";
      }
      w.write_header(h);
      ProgressBar bar = ProgressBar::on_stderr("converting " + file.path());
      ProgressTraceReader watched(*reader, bar);
      TraceEvent e;
      while (watched.next(e)) w.write(e);
      bar.finish();
      w.finish();
      if (stdout_buf) stdout_buf->close();
      return kTraceOk;
    }
    std::unique_ptr<FileBuf> file_buf;
    std::ostream file_out(nullptr);
    std::ostream* dst = to_stdout;
    if (args.output != "-") {
      file_buf = std::make_unique<FileBuf>(args.output, max_output);  // throws "OUT: cannot create: ..."
      file_out.rdbuf(file_buf.get());
      dst = &file_out;
    }
    // An export stops at its stream's first write error (std::ios_base::failure); the buffer
    // under the stream kept the reason, which the flush below reports.
    try {
      if (to == "ioctl") {
        std::unique_ptr<TraceReader> reader = file.read();
        const UmockdevExportStats s = export_umockdev_ioctl(*reader, *dst, args.device);
        if (s.frames_without_miso)
          err << "note: " << counted(s.frames_without_miso, "frame") << " without a complete MISO: written without R (don't care)\n";
      } else {
        // Streamed: each pass reads the file again (a native trace) or the trace imported once.
        const TracePasses passes = [&file] { return file.read(); };
        if (args.no_emulation) {
          export_vcd(passes, *dst, {args.timescale_ns});
        } else {
          const TraceWorld world = world_of(args.trace, file);
          Chain chain = world.make_chain();
          EmulatedVcdOptions o;
          o.timescale_ns = args.timescale_ns;
          o.sample_ticks = static_cast<Tick>(std::llround(args.sample_us * kTicksPerMicrosecond));
          export_emulated_vcd(passes, chain, *dst, o);
          err << "l6470emu: BUSY, FLAG and ABS_POS from an emulated chain " << world.summary() << " (" << world.how << ")\n";
          if (world.overrides) err << "note: " << world.override_note(file.path()) << "\n";
        }
      }
    } catch (const std::ios_base::failure&) {
      dst->setstate(std::ios::badbit);
    }
    errno = 0;
    dst->flush();
    if (file_buf) {
      file_buf->close();  // throws "OUT: write failed: <reason>"
    } else if (stdout_buf) {
      stdout_buf->close();  // throws "standard output: write failed: <reason>"
    } else if (!*dst) {
      const int e = errno;
      throw std::runtime_error(where + ": write failed" + (e != 0 ? std::string(": ") + std::strerror(e) : std::string()));
    }
    return kTraceOk;
  } catch (const std::exception& e) {
    err << "l6470emu convert: " << e.what() << "\n";
    return kTraceBadInput;
  }
}

}  // namespace l6470emu
