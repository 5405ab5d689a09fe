// libFuzzer harness of the native trace reader (spi/trace_native.cpp), from memory and from a
// file (the streaming path must read the same events or fail on the same line; a gzip input
// goes through zlib), its `repeat` lines both ways (compact write, read back), plus the
// format dispatcher and the in-process VCD exporter (spi/export_vcd.hpp) on what it reads. The
// VCD *reader* is sigrok-cli, a separate program: not fuzzed here.
#include <sys/mman.h>
#include <unistd.h>

#include "fuzz_support.hpp"
#include "spi/export_vcd.hpp"
#include "spi/trace_file.hpp"

using namespace l6470emu;

namespace {

/// Events read before the harness stops: a `repeat` line may stand for 10^12 frames, which
/// the reader hands out lazily; the harness does not wait for them all.
constexpr std::size_t kMaxEvents = 20'000;

/// Reads up to kMaxEvents events of `r` into `t`.
void read_capped(NativeTraceReader& r, Trace& t) {
  t.header = r.header();
  TraceEvent e;
  while (t.size() < kMaxEvents && r.next(e)) t.write(e);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::count_input(size);
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  if (starts_with_gzip_magic(text)) {
    // gzip is read from files only: zlib on damaged, cut or lying compressed data.
    int fd = -1;
    const std::string path = fuzz::as_file(data, size, fd);
    if (path.empty()) return 0;
    try {
      NativeTraceReader r(path);
      Trace t;
      read_capped(r, t);
      fuzz::check_trace(t);
    } catch (const TraceError& e) {
      fuzz::check_error_line(e, path);
    }
    ::close(fd);
    return 0;
  }
  std::string memory_error;
  Trace from_memory;
  try {
    NativeTraceReader r(text, "fuzz.trace");
    read_capped(r, from_memory);
  } catch (const TraceError& e) {
    fuzz::check_error_line(e, "fuzz.trace");
    memory_error = e.what();
  }

  // The streaming reader on the same bytes.
  int fd = -1;
  const std::string path = fuzz::as_file(data, size, fd);
  if (!path.empty()) {
    std::string file_error;
    Trace from_file;
    try {
      NativeTraceReader r(path);
      read_capped(r, from_file);
    } catch (const TraceError& e) {
      file_error = e.what();
    }
    ::close(fd);
    // Same message apart from the file's name.
    auto strip = [](const std::string& m, const std::string& name) {
      return m.rfind(name, 0) == 0 ? m.substr(name.size()) : m;
    };
    FUZZ_CHECK(strip(memory_error, "fuzz.trace") == strip(file_error, path),
               "reading from memory and from a file differ:\n  %.300s\n  %.300s", memory_error.c_str(),
               file_error.c_str());
    if (memory_error.empty()) fuzz::check_same_events(from_memory, from_file, "memory vs file");
  }

  // The dispatcher on what detection says (any format).
  try {
    const TraceFormat f = detect_trace_format(text.substr(0, 64 * 1024), "fuzz.trace");
    if (f != TraceFormat::native) (void)import_trace(text, "fuzz.trace", f);
  } catch (const TraceError& e) {
    fuzz::check_error_line(e, "fuzz.trace");
  }

  if (!memory_error.empty()) return 0;
  fuzz::check_trace(from_memory);
  fuzz::check_native_round_trip(from_memory);
  // Written with `repeat` lines, it reads back to the same events too.
  try {
    fuzz::check_same_events(from_memory, read_native_trace(to_native_text(from_memory, true), "compact"),
                            "compact round trip");
  } catch (const TraceError& e) {
    fuzz::violated("the compact native text of a trace does not read back: %.300s", e.what());
  }
  fuzz::decode_and_replay(from_memory);
  fuzz::NullStream out;
  export_vcd(from_memory, out, VcdOptions{static_cast<unsigned>(size % 3 == 0 ? 1 : size % 3 == 1 ? 10 : 100)});
  return 0;
}
