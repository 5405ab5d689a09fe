// Shared pieces of the readers (internal to spi/): lines with their numbers, quoting input
// in messages, and a builder that turns capture times into ticks while checking that time
// goes forward.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <span>
#include <string>
#include <string_view>

#include "spi/trace.hpp"

namespace l6470emu::detail {

/// Walks a text line by line, counting lines from 1; '\r' before '\n' is dropped.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text) : rest_(text) {}
  bool next(std::string_view& line) {
    if (rest_.empty()) return false;
    const void* nl = std::memchr(rest_.data(), '\n', rest_.size());
    std::size_t len;
    if (nl == nullptr) {
      len = rest_.size();
      unterminated_ = true;
      line = rest_;
      rest_ = {};
    } else {
      len = static_cast<std::size_t>(static_cast<const char*>(nl) - rest_.data());
      line = rest_.substr(0, len);
      rest_.remove_prefix(len + 1);
    }
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    ++number_;
    return true;
  }
  std::uint64_t number() const { return number_; }
  /// Whether the line just read ended the file without a newline.
  bool unterminated() const { return unterminated_; }

 private:
  std::string_view rest_;
  std::uint64_t number_ = 0;
  bool unterminated_ = false;
};

/// Longest stretch of input a message quotes (bytes; a longer one is cut and ends in "…").
inline constexpr std::size_t kQuoteMax = 60;

/// The length of the well-formed UTF-8 sequence of 2 to 4 bytes at s[i], or 0.
inline std::size_t utf8_sequence(std::string_view s, std::size_t i) {
  const auto c = static_cast<unsigned char>(s[i]);
  const std::size_t len = c >= 0xC2 && c <= 0xDF ? 2 : c >= 0xE0 && c <= 0xEF ? 3 : c >= 0xF0 && c <= 0xF4 ? 4 : 0;
  if (len == 0 || i + len > s.size()) return 0;
  for (std::size_t k = 1; k < len; ++k)
    if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return 0;
  return len;
}


/// Input text for a message: cut after kQuoteMax bytes (never inside a UTF-8 sequence) with
/// "…" appended, control characters as \xNN, so that one bad token of a huge or binary file
/// still gives one short, printable line. Bytes that are not part of a well-formed UTF-8
/// sequence (a binary file, Latin-1 text) are shown as \xNN too, so the line names the byte.
inline std::string printable(std::string_view s) {
  std::size_t n = s.size();
  if (n > kQuoteMax) {
    n = kQuoteMax;
    while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;  // a UTF-8 continuation byte
  }
  std::string q;
  q.reserve(n + 4);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c >= 0x80) {
      if (const std::size_t len = utf8_sequence(s.substr(0, n), i); len != 0) {
        q.append(s.substr(i, len));
        i += len - 1;
        continue;
      }
    }
    if (c < 0x20 || c >= 0x7F) {
      static constexpr char kHex[] = "0123456789ABCDEF";
      q += "\\x";
      q += kHex[c >> 4];
      q += kHex[c & 15];
    } else {
      q += static_cast<char>(c);
    }
  }
  if (n < s.size()) q += "\xE2\x80\xA6";  // "…" in UTF-8
  return q;
}

/// printable(s) in double quotes.
inline std::string quote(std::string_view s) { return '"' + printable(s) + '"'; }

/// Splits off the next token of `rest`, tokens being separated by blanks, tabs and carriage
/// returns (a native trace's fields).
inline std::string_view next_token(std::string_view& rest) {
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  std::size_t i = 0;
  while (i < rest.size() && is_space(rest[i])) ++i;
  std::size_t j = i;
  while (j < rest.size() && !is_space(rest[j])) ++j;
  const std::string_view tok = rest.substr(i, j - i);
  rest.remove_prefix(j);
  return tok;
}

/// Appends frames to a Trace in capture order: times become ticks counted from the first
/// frame's start (rounded to nearest); going backwards or overlapping frames is an error.
/// At most `max_frames` frames (0: no limit) and kMaxTraceFrameBytes bytes a frame are taken.
class FrameBuilder {
 public:
  FrameBuilder(Trace& trace, const std::string& name, std::uint64_t max_frames = kDefaultMaxTraceFrames)
      : trace_(trace), name_(name), max_frames_(max_frames) {}

  /// Throws the TraceError for a trace with more than max_frames frames, at `line`.
  static void check_frame_count(const Trace& trace, const std::string& name, std::uint64_t max_frames,
                                std::uint64_t line) {
    if (max_frames != 0 && trace.frame_count() >= max_frames)
      throw TraceError(name, line, "the trace holds " + too_many_frames(max_frames));
  }

  void frame(const SourceTime& start, const SourceTime& end, std::span<const std::uint8_t> mosi,
             std::span<const std::uint8_t> miso, std::span<const std::uint8_t> known, std::uint64_t line) {
    check_frame_count(trace_, name_, max_frames_, line);
    if (mosi.size() > kMaxTraceFrameBytes) throw TraceError(name_, line, frame_too_long(mosi.size()));
    if (!started_) {
      origin_ = start;
      started_ = true;
    } else {
      if (start < last_start_)
        throw TraceError(name_, line, "time " + seconds(start) + " s goes backwards (the previous frame began at " +
                                          seconds(last_start_) + " s)");
      if (start < last_end_)
        throw TraceError(name_, line, "frame at " + seconds(start) + " s begins before the previous one ended (" +
                                          seconds(last_end_) + " s)");
    }
    if (end < start)
      throw TraceError(name_, line, "frame ends (" + seconds(end) + " s) before it begins (" + seconds(start) + " s)");
    TraceEvent e;
    e.kind = TraceEventKind::frame;
    if (!ticks_between(origin_, start, e.tick))
      throw TraceError(name_, line, "time " + seconds(start) + " s is too far from the first frame");
    Tick end_tick = 0;
    if (!ticks_between(origin_, end, end_tick))
      throw TraceError(name_, line, "time " + seconds(end) + " s is too far from the first frame");
    e.duration = end_tick - e.tick;
    e.mosi = mosi;
    e.miso = miso;
    e.miso_known = known;
    e.line = line;
    e.source_time = start.to_double();
    trace_.write(e);
    last_start_ = start;
    last_end_ = end;
  }

  static std::string seconds(const SourceTime& t) {
    char buf[48];
    if (t.seconds < 0 && t.picoseconds != 0)
      std::snprintf(buf, sizeof buf, "-%lld.%012lld", static_cast<long long>(-t.seconds - 1),
                    static_cast<long long>(1'000'000'000'000 - t.picoseconds));
    else
      std::snprintf(buf, sizeof buf, "%lld.%012lld", static_cast<long long>(t.seconds),
                    static_cast<long long>(t.picoseconds));
    // Trim trailing zeros, keep at least one decimal.
    std::string s = buf;
    while (s.size() > 2 && s.back() == '0' && s[s.size() - 2] != '.') s.pop_back();
    return s;
  }

 private:
  Trace& trace_;
  const std::string& name_;
  std::uint64_t max_frames_;
  bool started_ = false;
  SourceTime origin_, last_start_, last_end_;
};

}  // namespace l6470emu::detail
