// Shared pieces of the libFuzzer harnesses: an invariant check that traps (so libFuzzer
// keeps the input), an output stream that discards, and "run what a reader produced through
// decode and replay" for the trace-reader harnesses. Header-only; harnesses only.
#pragma once

#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <ostream>
#include <stdexcept>
#include <streambuf>
#include <string>
#include <vector>

#include "daisychain/chain.hpp"
#include "daisychain/chain_spec.hpp"
#include "daisychain/decode.hpp"
#include "daisychain/replay.hpp"
#include "spi/trace.hpp"
#include "spi/trace_import.hpp"
#include "spi/trace_file.hpp"
#include "spi/trace_native.hpp"

namespace l6470emu::fuzz {

/// Prints what broke and stops with a trap: libFuzzer saves the input as a crash.
[[noreturn]] inline void violated(const char* format, ...) {
  va_list args;
  va_start(args, format);
  std::fputs("INVARIANT VIOLATED: ", stderr);
  std::vfprintf(stderr, format, args);
  std::fputc('\n', stderr);
  va_end(args);
  std::fflush(stderr);
  __builtin_trap();
}

#define FUZZ_CHECK(cond, ...)                              \
  do {                                                     \
    if (!(cond)) ::l6470emu::fuzz::violated(__VA_ARGS__);  \
  } while (0)

/// Counts the input bytes a harness was given; printed at exit as "stat::input_bytes: N"
/// beside libFuzzer's own -print_final_stats lines.
inline void count_input(std::size_t size) {
  static struct Counter {
    std::uint64_t bytes = 0;
    ~Counter() {
      if (bytes) std::fprintf(stderr, "stat::input_bytes: %llu\n", static_cast<unsigned long long>(bytes));
    }
  } counter;
  counter.bytes += size;
}

/// An ostream that throws everything away (decode output).
class NullStream : public std::ostream {
 public:
  NullStream() : std::ostream(&buf_) {}

 private:
  struct Buf : std::streambuf {
    int overflow(int c) override { return c == traits_type::eof() ? 0 : c; }
    std::streamsize xsputn(const char*, std::streamsize n) override { return n; }
  } buf_;
};

/// A TraceError must be one line that names the file: "name:line: message" or "name: message".
inline void check_error_line(const TraceError& e, const std::string& name) {
  const std::string what = e.what();
  FUZZ_CHECK(what.rfind(name, 0) == 0, "error does not start with the file name: %.200s", what.c_str());
  FUZZ_CHECK(what.find('\n') == std::string::npos, "error is not one line: %.200s", what.c_str());
  // Quoted input is cut short: no message may echo a long stretch of the file.
  FUZZ_CHECK(what.size() < 1200, "error of %zu characters: %.200s", what.size(), what.c_str());
}

/// The chain a fuzzed trace runs through: its own chain line when that parses to at most
/// 8 chips, else as many L6470s as its first frame is long (1..8).
inline Chain chain_for(const Trace& t) {
  if (!t.header.chain.empty()) {
    try {
      const std::vector<const Variant*> v = parse_chain_spec(t.header.chain);
      if (v.size() <= 8) return make_chain(v);
    } catch (const std::invalid_argument&) {
    }
  }
  std::size_t n = 1;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (t[i].kind == TraceEventKind::frame && !t[i].mosi.empty()) {
      n = t[i].mosi.size();
      break;
    }
  return Chain(n < 1 ? 1 : n > 8 ? 8 : n);
}

/// What the command-line tools do with a trace a reader produced: decode it and replay it
/// (errors about chips outside the chain are fine, crashes are not).
inline void decode_and_replay(const Trace& t) {
  {
    Chain chain = chain_for(t);
    NullStream out;
    auto reader = t.reader();
    try {
      decode_trace(*reader, chain, out, DecodeOptions{});
    } catch (const TraceError& e) {
      check_error_line(e, t.header.name);
    }
  }
  {
    Chain chain = chain_for(t);
    auto reader = t.reader();
    ReplayOptions options;
    options.keep_going = true;
    options.max_reports = 4;
    try {
      replay_trace(*reader, chain, options);
    } catch (const TraceError& e) {
      check_error_line(e, t.header.name);
    }
  }
}

/// Whatever a reader produced must be a well-formed trace: events in time order, frames not
/// overlapping, MISO and its mask as long as MOSI.
inline void check_trace(const Trace& t) {
  Tick last = 0, frame_end = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const TraceEvent e = t[i];
    FUZZ_CHECK(e.tick >= last, "event %zu goes back in time", i);
    last = e.tick;
    if (e.kind != TraceEventKind::frame) continue;
    FUZZ_CHECK(e.tick >= frame_end, "frame %zu begins before the previous one ended", i);
    frame_end = e.end();
    FUZZ_CHECK(e.miso.empty() || e.miso.size() == e.mosi.size(), "frame %zu: %zu MOSI but %zu MISO bytes", i,
               e.mosi.size(), e.miso.size());
    FUZZ_CHECK(e.miso_known.empty() || e.miso_known.size() == e.mosi.size(), "frame %zu: mask of %zu bytes", i,
               e.miso_known.size());
  }
}

/// Two traces hold the same events (times, bytes, pins, faults).
inline void check_same_events(const Trace& a, const Trace& b, const char* what) {
  FUZZ_CHECK(a.size() == b.size(), "%s: %zu events, then %zu", what, a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const TraceEvent x = a[i], y = b[i];
    FUZZ_CHECK(x.kind == y.kind && x.tick == y.tick, "%s: event %zu differs in kind or time", what, i);
    if (x.kind == TraceEventKind::frame) {
      FUZZ_CHECK(x.duration == y.duration, "%s: frame %zu duration %llu, then %llu", what, i,
                 static_cast<unsigned long long>(x.duration), static_cast<unsigned long long>(y.duration));
      FUZZ_CHECK(std::equal(x.mosi.begin(), x.mosi.end(), y.mosi.begin(), y.mosi.end()), "%s: frame %zu MOSI differs",
                 what, i);
      FUZZ_CHECK(x.miso.size() == y.miso.size(), "%s: frame %zu MISO length differs", what, i);
      FUZZ_CHECK(x.wire.same_as(y.wire), "%s: frame %zu host wire settings differ", what, i);
      for (std::size_t k = 0; k < x.miso.size(); ++k) {
        FUZZ_CHECK(x.miso_byte_known(k) == y.miso_byte_known(k), "%s: frame %zu MISO byte %zu known differs", what, i,
                   k);
        FUZZ_CHECK(!x.miso_byte_known(k) || x.miso[k] == y.miso[k], "%s: frame %zu MISO byte %zu differs", what, i, k);
      }
    } else {
      FUZZ_CHECK(x.chip == y.chip && x.value == y.value &&
                     (x.kind == TraceEventKind::pin ? x.pin == y.pin : x.fault == y.fault),
                 "%s: event %zu differs", what, i);
    }
  }
}

/// A trace written in the native format reads back to the same events.
inline void check_native_round_trip(const Trace& t) {
  const std::string text = to_native_text(t);
  try {
    const Trace back = read_native_trace(text, "round-trip");
    check_same_events(t, back, "native round trip");
  } catch (const TraceError& e) {
    violated("the native text of a trace does not read back: %.300s", e.what());
  }
}

/// The input as a file (a memfd, named through /proc) for the readers that stream a file; `fd`
/// gets the descriptor to close. Empty when no memfd could be made.
inline std::string as_file(const std::uint8_t* data, std::size_t size, int& fd) {
  fd = memfd_create("fuzz.input", MFD_CLOEXEC);
  if (fd < 0) return {};
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n <= 0) break;
    done += static_cast<std::size_t>(n);
  }
  return "/proc/self/fd/" + std::to_string(fd);
}

/// Runs one reader over the input: a trace (checked, written back, decoded and replayed) or
/// a one-line TraceError naming the file. Anything else escapes and is a crash. The same bytes
/// are also read as a file, streamed a chunk at a time (import_trace_file with `format` and
/// `options`, as the l6470emu program reads them): the same events or the same error, and a
/// gzip input goes through zlib there.
template <class Import>
void run_reader(const std::uint8_t* data, std::size_t size, const std::string& name, Import import, TraceFormat format,
                const ImportOptions& options = {}) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  (void)detect_trace_format(text.substr(0, 64 * 1024), name);
  Trace t;
  std::string memory_error;
  try {
    t = import(text, name);
  } catch (const TraceError& e) {
    check_error_line(e, name);
    memory_error = e.what();
  }

  int fd = -1;
  const std::string path = as_file(data, size, fd);
  if (!path.empty()) {
    Trace from_file;
    std::string file_error;
    try {
      from_file = import_trace_file(path, format, options);
    } catch (const TraceError& e) {
      check_error_line(e, path);
      file_error = e.what();
    }
    ::close(fd);
    if (starts_with_gzip_magic(text)) {
      if (file_error.empty()) check_trace(from_file);  // what the text was compressed from
    } else {
      auto strip = [](const std::string& m, const std::string& n) { return m.rfind(n, 0) == 0 ? m.substr(n.size()) : m; };
      FUZZ_CHECK(strip(memory_error, name) == strip(file_error, path),
                 "reading from memory and from a file differ:\n  %.300s\n  %.300s", memory_error.c_str(),
                 file_error.c_str());
      if (memory_error.empty()) check_same_events(t, from_file, "memory vs file");
    }
  }
  if (!memory_error.empty()) return;
  check_trace(t);
  check_native_round_trip(t);
  decode_and_replay(t);
}

}  // namespace l6470emu::fuzz
