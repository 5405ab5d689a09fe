// sigrok-cli's JSON trace of the spi decoder (--protocol-decoder-jsontrace, Chrome trace
// format): {"traceEvents": [{"ph": "B"|"E", "ts": µs, "pid": "spi-1", "tid": "MOSI transfer",
// "name": "21 D0"}, ...]}. CS frames from the MOSI/MISO transfer annotations (the decoder
// needs a cs channel for them), else one frame per MOSI/MISO data byte.
#include <algorithm>
#include <cctype>
#include <map>
#include <vector>

#include "spi/import_support.hpp"
#include "spi/trace_import.hpp"

namespace l6470emu {
namespace {

using detail::FrameBuilder;
using detail::quote;

/// One annotation event, the fields the spi decoder writes.
struct JsonEvent {
  std::string ph, pid, tid, name;
  std::string_view ts;  // the number as written
  std::uint64_t line = 0;
};

/// A small JSON reader that knows its line number; only what a Chrome trace needs.
class Json {
 public:
  Json(std::string_view text, const std::string& name) : s_(text), name_(name) {}

  std::vector<JsonEvent> events() {
    std::vector<JsonEvent> out;
    skip_ws();
    if (peek() == '[') {
      read_event_array(out);
    } else if (peek() == '{') {
      bool found = false;
      read_members([&](const std::string& key) {
        if (key == "traceEvents") {
          read_event_array(out);
          found = true;
        } else {
          skip_value();
        }
      });
      if (!found) fail("no \"traceEvents\" array (expected sigrok-cli --protocol-decoder-jsontrace output)");
    } else {
      fail("not JSON (expected sigrok-cli --protocol-decoder-jsontrace output, which starts with '{')");
    }
    skip_ws();
    if (i_ != s_.size()) fail("text after the end of the JSON document");
    return out;
  }

  [[noreturn]] void fail(const std::string& message) const { throw TraceError(name_, line_, message); }

 private:
  /// Reads an object; on_member(key) is called with the member's value next in line and must read it.
  template <class F>
  void read_members(F on_member) {
    expect('{');
    for (bool first = true;; first = false) {
      skip_ws();
      if (peek() == '}') {
        ++i_;
        return;
      }
      if (!first) {
        expect(',');
        skip_ws();
      }
      const std::string key = read_string();
      skip_ws();
      expect(':');
      skip_ws();
      on_member(key);
    }
  }

  char peek() const { return i_ < s_.size() ? s_[i_] : '\0'; }
  void skip_ws() {
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (c == '\n') ++line_;
      else if (c != ' ' && c != '\t' && c != '\r') break;
      ++i_;
    }
  }
  void expect(char c) {
    if (i_ >= s_.size()) fail(std::string("unexpected end of file, expected '") + c + "' (truncated file?)");
    if (s_[i_] != c) fail(std::string("expected '") + c + "', found '" + s_[i_] + "'");
    ++i_;
  }
  std::string read_string() {
    expect('"');
    std::string out;
    for (;;) {
      if (i_ >= s_.size()) fail("unterminated string (truncated file?)");
      const char c = s_[i_++];
      if (c == '"') return out;
      if (c == '\n') fail("newline inside a string");
      if (c != '\\') {
        out += c;
        continue;
      }
      if (i_ >= s_.size()) fail("unterminated string (truncated file?)");
      const char e = s_[i_++];
      switch (e) {
        case 'n': out += '\n'; break;
        case 't': out += '\t'; break;
        case 'r': out += '\r'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'u': {
          if (i_ + 4 > s_.size()) fail("bad \\u escape");
          unsigned v = 0;
          for (int k = 0; k < 4; ++k) {
            const int d = hex_digit_value(s_[i_++]);
            if (d < 0) fail("bad \\u escape");
            v = v * 16 + static_cast<unsigned>(d);
          }
          out += v < 0x80 ? static_cast<char>(v) : '?';
          break;
        }
        default: out += e; break;
      }
    }
  }
  std::string_view read_number() {
    const std::size_t b = i_;
    while (i_ < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[i_])) || s_[i_] == '-' || s_[i_] == '+' ||
                              s_[i_] == '.' || s_[i_] == 'e' || s_[i_] == 'E'))
      ++i_;
    if (b == i_) fail("expected a value");
    return s_.substr(b, i_ - b);
  }
  void skip_value() {
    skip_ws();
    const char c = peek();
    if (c == '"') {
      read_string();
    } else if (c == '{' || c == '[') {
      const char close = c == '{' ? '}' : ']';
      ++i_;
      for (bool first = true;; first = false) {
        skip_ws();
        if (peek() == close) {
          ++i_;
          return;
        }
        if (!first) {
          expect(',');
          skip_ws();
        }
        if (c == '{') {
          read_string();
          skip_ws();
          expect(':');
        }
        skip_value();
      }
    } else if (s_.substr(i_, 4) == "true" || s_.substr(i_, 4) == "null") {
      i_ += 4;
    } else if (s_.substr(i_, 5) == "false") {
      i_ += 5;
    } else if (i_ >= s_.size()) {
      fail("unexpected end of file (truncated file?)");
    } else {
      read_number();
    }
  }
  void read_event_array(std::vector<JsonEvent>& out) {
    skip_ws();
    expect('[');
    for (bool first = true;; first = false) {
      skip_ws();
      if (peek() == ']') {
        ++i_;
        return;
      }
      if (!first) {
        expect(',');
        skip_ws();
      }
      JsonEvent e;
      e.line = line_;
      read_members([&](const std::string& key) {
        if (key == "ts") {
          if (peek() == '"') fail("\"ts\" must be a number");
          e.ts = read_number();
        } else if (key == "ph" || key == "pid" || key == "tid" || key == "name") {
          if (peek() != '"') fail("\"" + key + "\" must be a string");
          std::string v = read_string();
          if (key == "ph") e.ph = std::move(v);
          else if (key == "pid") e.pid = std::move(v);
          else if (key == "tid") e.tid = std::move(v);
          else e.name = std::move(v);
        } else {
          skip_value();
        }
      });
      out.push_back(std::move(e));
    }
  }

  std::string_view s_;
  const std::string& name_;
  std::size_t i_ = 0;
  std::uint64_t line_ = 1;
};

/// An annotation from its B to its E event.
struct Span {
  SourceTime begin, end;
  std::vector<std::uint8_t> bytes;
  std::uint64_t line = 0;
};

void parse_bytes(const std::string& name, const JsonEvent& e, const char* what, std::vector<std::uint8_t>& out) {
  std::string_view s = e.name;
  while (!s.empty()) {
    while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
    if (s.empty()) break;
    std::size_t n = s.find(' ');
    if (n == std::string_view::npos) n = s.size();
    const std::string_view tok = s.substr(0, n);
    if (tok.size() != 2 || hex_digit_value(tok[0]) < 0 || hex_digit_value(tok[1]) < 0)
      throw TraceError(name, e.line,
                       std::string(what) + " " + quote(tok) + " is not a byte (set the spi decoder to 8-bit words)");
    out.push_back(static_cast<std::uint8_t>(hex_digit_value(tok[0]) << 4 | hex_digit_value(tok[1])));
    s.remove_prefix(n);
  }
}

}  // namespace

Trace import_sigrok_json(std::string_view text, const std::string& name, const ImportOptions& options) {
  Trace trace;
  trace.header.name = name;
  trace.header.format = "sigrok";
  Json json(text, name);
  const std::vector<JsonEvent> events = json.events();

  // Which decoder instance.
  std::string pid = options.select;
  if (pid.empty()) {
    for (const JsonEvent& e : events) {
      if (e.tid.rfind("MOSI", 0) != 0 && e.tid.rfind("MISO", 0) != 0) continue;
      if (pid.empty()) pid = e.pid;
      else if (e.pid != pid)
        throw TraceError(name, e.line, "annotations of several spi decoders (" + quote(pid) + " and " + quote(e.pid) +
                                           "): choose one with --select");
    }
  }
  bool transfers = false;
  for (const JsonEvent& e : events)
    if (e.pid == pid && (e.tid == "MOSI transfer" || e.tid == "MISO transfer")) transfers = true;
  const std::string mosi_tid = transfers ? "MOSI transfer" : "MOSI data";
  const std::string miso_tid = transfers ? "MISO transfer" : "MISO data";

  // Pair B with E per track.
  std::vector<Span> mosi, miso;
  std::map<std::string, std::pair<bool, Span>> open;  // tid -> (open?, span)
  for (const JsonEvent& e : events) {
    if (e.pid != pid || (e.tid != mosi_tid && e.tid != miso_tid)) continue;
    const char* what = e.tid == mosi_tid ? "MOSI" : "MISO";
    SourceTime t;
    if (!parse_source_time(e.ts, -6, t))
      throw TraceError(name, e.line, "\"ts\" " + quote(e.ts) + " is not a time in microseconds");
    auto& [is_open, span] = open[e.tid];
    if (e.ph == "B") {
      if (is_open) throw TraceError(name, e.line, std::string(what) + " annotation begins while the one of line " +
                                                      std::to_string(span.line) + " is still open");
      is_open = true;
      span = Span{};
      span.begin = t;
      span.line = e.line;
      parse_bytes(name, e, what, span.bytes);
    } else if (e.ph == "E") {
      if (!is_open) throw TraceError(name, e.line, std::string(what) + " annotation ends without a begin");
      if (t < span.begin) throw TraceError(name, e.line, "time goes backwards: the annotation ends before it begins");
      span.end = t;
      is_open = false;
      (e.tid == mosi_tid ? mosi : miso).push_back(std::move(span));
    } else {
      throw TraceError(name, e.line, "\"ph\" " + quote(e.ph) + " is neither B nor E");
    }
  }
  for (const auto& [tid, o] : open)
    if (o.first) throw TraceError(name, o.second.line, tid + " annotation never ends (truncated file?)");
  if (mosi.empty()) {
    if (!miso.empty())
      throw TraceError(name, miso.front().line, "MISO annotations but no MOSI: give the spi decoder a mosi channel");
    throw TraceError(name, 0, "no spi decoder annotations (run sigrok-cli -P spi:...:cs=CS --protocol-decoder-jsontrace)");
  }
  if (!transfers)
    trace.header.notes.push_back(
        "no MOSI/MISO transfer annotations (the decoder had no cs channel): each byte is taken as its own CS frame");
  if (miso.empty()) trace.header.notes.push_back("no MISO annotations: MISO bytes are unknown and not compared");

  // Match MISO spans to MOSI spans by their begin time (the decoder emits both for each
  // frame, in time order; FrameBuilder rejects times that go backwards).
  FrameBuilder frames(trace, name);
  std::size_t j = 0;
  for (const Span& m : mosi) {
    if (j < miso.size() && miso[j].begin < m.begin)
      throw TraceError(name, miso[j].line, "MISO annotation at " + FrameBuilder::seconds(miso[j].begin) +
                                               " s has no MOSI annotation beside it");
    const Span* r = j < miso.size() && miso[j].begin == m.begin ? &miso[j++] : nullptr;
    if (r != nullptr && r->bytes.size() != m.bytes.size())
      throw TraceError(name, r->line, "MOSI has " + std::to_string(m.bytes.size()) + " bytes but MISO has " +
                                          std::to_string(r->bytes.size()) + " in the frame at " +
                                          FrameBuilder::seconds(m.begin) + " s");
    const std::span<const std::uint8_t> rx = r != nullptr ? std::span<const std::uint8_t>(r->bytes)
                                                          : std::span<const std::uint8_t>{};
    frames.frame(m.begin, std::max(m.end, r != nullptr ? r->end : m.end), m.bytes, rx, {}, m.line);
  }
  return trace;
}

}  // namespace l6470emu
