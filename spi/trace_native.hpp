// The native trace format (docs/trace-format.md): line-based text, one CS frame per
// line, version 1. Reader (streaming, for traces of any length) and writer (flushed
// event by event, so a killed process leaves a complete file). No other formats here.
#pragma once

#include <cstdint>
#include <cstdio>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "spi/trace.hpp"

namespace l6470emu {

/// The first line of every native trace.
inline constexpr std::string_view kNativeTraceMagic = "l6470emu-trace";
/// The format version this code writes and reads.
inline constexpr int kNativeTraceVersion = 1;

/// Reads a native trace event by event; memory use does not grow with its length.
class NativeTraceReader final : public TraceReader {
 public:
  /// Opens `path`. Throws TraceError when it cannot be read or is not a version-1 native trace.
  explicit NativeTraceReader(const std::string& path);
  /// Reads `text` (kept by reference: it must outlive the reader), called `name` in messages.
  NativeTraceReader(std::string_view text, std::string name);
  ~NativeTraceReader() override;
  NativeTraceReader(const NativeTraceReader&) = delete;
  NativeTraceReader& operator=(const NativeTraceReader&) = delete;

  const TraceHeader& header() const override { return header_; }
  bool next(TraceEvent& e) override;

 private:
  bool next_line(std::string_view& line);
  bool parse_line(std::string_view line, TraceEvent& e);
  void read_header();
  [[noreturn]] void fail(const std::string& message) const;

  TraceHeader header_;
  std::FILE* file_ = nullptr;
  std::vector<char> buffer_;
  std::string_view text_;     // unread text (whole input in string mode, buffered part in file mode)
  bool eof_ = false;
  bool last_line_unterminated_ = false;
  std::uint64_t line_no_ = 0;
  bool have_pending_ = false;  // read_header() stopped at the first event
  TraceEvent pending_;
  bool any_event_ = false;
  Tick last_tick_ = 0;
  Tick last_frame_end_ = 0;
  std::vector<std::uint8_t> mosi_, miso_, known_;
};

/// Writes a native trace. Every event is one line, handed to the OS (fflush) before
/// write() returns unless `flush_each_event` is false.
class NativeTraceWriter final : public TraceSink {
 public:
  /// Creates or truncates `path`. Throws std::runtime_error when it cannot.
  explicit NativeTraceWriter(const std::string& path, bool flush_each_event = true);
  /// Writes to `out` (flushed after every event when `flush_each_event`).
  explicit NativeTraceWriter(std::ostream& out, bool flush_each_event = true);
  ~NativeTraceWriter() override;
  NativeTraceWriter(const NativeTraceWriter&) = delete;
  NativeTraceWriter& operator=(const NativeTraceWriter&) = delete;

  void write_header(const TraceHeader& header) override;
  void write(const TraceEvent& e) override;

  /// One event as its native line, without the newline.
  static std::string format_event(const TraceEvent& e);

 private:
  void put(const std::string& text);

  std::FILE* file_ = nullptr;
  std::ostream* out_ = nullptr;
  std::string path_;
  bool flush_;
  bool header_written_ = false;
  std::string line_;
};

/// A native trace as text (header and every event).
std::string to_native_text(const Trace& trace);

/// Reads a whole native trace into memory.
Trace read_native_trace(std::string_view text, const std::string& name);

}  // namespace l6470emu
