// sigrok-cli's JSON trace of the spi decoder (--protocol-decoder-jsontrace, Chrome trace
// format): {"traceEvents": [{"ph": "B"|"E", "ts": µs, "pid": "spi-1", "tid": "MOSI transfer",
// "name": "21 D0"}, ...]}. CS frames from the MOSI/MISO transfer annotations (the decoder
// needs a cs channel for them), else one frame per MOSI/MISO data byte. JSON is read with
// nlohmann-json's SAX parser (iterative, nesting capped); line numbers come from the byte offset.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <iterator>
#include <map>
#include <vector>

#include "spi/import_support.hpp"
#include "spi/trace_import.hpp"

namespace l6470emu {
namespace {

using detail::FrameBuilder;
using detail::quote;
using Json = nlohmann::json;

/// Deeper nesting than this is refused (a Chrome trace needs 4 levels; arbitrary "args" a few more).
constexpr std::size_t kMaxDepth = 512;

/// One annotation event, the fields the spi decoder writes.
struct JsonEvent {
  std::string ph, pid, tid, name;
  std::string ts;  // the number as written
  std::uint64_t line = 0;
};

/// A character iterator over the text that publishes how far the parser has read, so the
/// SAX handler (which nlohmann tells nothing about positions) can name lines.
class TrackingIterator {
 public:
  using iterator_category = std::input_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = const char&;

  TrackingIterator(const char* p, const char** cursor) : p_(p), cursor_(cursor) {}
  reference operator*() const { return *p_; }
  TrackingIterator& operator++() {
    *cursor_ = ++p_;
    return *this;
  }
  TrackingIterator operator++(int) {
    TrackingIterator old = *this;
    ++*this;
    return old;
  }
  friend bool operator!=(const TrackingIterator& a, const TrackingIterator& b) { return a.p_ != b.p_; }

 private:
  const char* p_;
  const char** cursor_;
};

/// Line numbers of byte offsets, counted incrementally (offsets mostly grow).
class LineCounter {
 public:
  explicit LineCounter(std::string_view text) : text_(text) {}
  /// Line (from 1) of the byte at `offset` (the end of the text counts as its last line).
  std::uint64_t line_of(std::size_t offset) {
    offset = std::min(offset, text_.size());
    if (offset < at_) {
      at_ = 0;
      line_ = 1;
    }
    line_ += static_cast<std::uint64_t>(std::count(text_.begin() + static_cast<std::ptrdiff_t>(at_),
                                                   text_.begin() + static_cast<std::ptrdiff_t>(offset), '\n'));
    at_ = offset;
    return line_;
  }

 private:
  std::string_view text_;
  std::size_t at_ = 0;
  std::uint64_t line_ = 1;
};

/// Collects the events of a Chrome trace from nlohmann's SAX callbacks. Knows where it is:
/// the containers open around it and what the parser expects next (for truncated files).
class EventCollector final : public nlohmann::json_sax<Json> {
 public:
  EventCollector(std::string_view text, const std::string& name) : text_(text), name_(name), lines_(text) {}

  /// Parses the whole text into events; throws TraceError naming the line of the problem.
  std::vector<JsonEvent> parse() {
    std::size_t i = 0;
    while (i < text_.size() && (text_[i] == ' ' || text_[i] == '\t' || text_[i] == '\r' || text_[i] == '\n')) ++i;
    if (i == text_.size() || (text_[i] != '{' && text_[i] != '['))
      throw TraceError(name_, lines_.line_of(i),
                       "not JSON (expected sigrok-cli --protocol-decoder-jsontrace output, which starts with '{')");
    cursor_ = text_.data();
    const TrackingIterator first(text_.data(), &cursor_), last(text_.data() + text_.size(), &cursor_);
    if (!Json::sax_parse(first, last, this)) throw TraceError(name_, error_line_, error_);
    if (!events_seen_)
      throw TraceError(name_, 0, "no \"traceEvents\" array (expected sigrok-cli --protocol-decoder-jsontrace output)");
    return std::move(events_);
  }

  // ---- nlohmann::json_sax ----------------------------------------------------

  bool null() override { return scalar(Kind::other, {}); }
  bool boolean(bool) override { return scalar(Kind::other, {}); }
  bool number_integer(number_integer_t v) override { return scalar(Kind::number, std::to_string(v)); }
  bool number_unsigned(number_unsigned_t v) override { return scalar(Kind::number, std::to_string(v)); }
  bool number_float(number_float_t, const string_t& text) override { return scalar(Kind::number, text); }
  bool string(string_t& s) override { return scalar(Kind::string, std::move(s)); }
  bool binary(binary_t&) override { return scalar(Kind::other, {}); }

  bool start_object(std::size_t) override {
    if (!may_open(Container::object)) return false;
    stack_.push_back(Container::object);
    if (events_depth_ != kNone && depth() == events_depth_ + 1) {
      event_ = JsonEvent{};
      event_.line = lines_.line_of(offset() - 1);  // the '{' just read
    }
    expect_ = Expect::key_or_end;
    open_end_ = offset();
    return true;
  }
  bool key(string_t& k) override {
    if (depth() == 1 && stack_[0] == Container::object) top_key_ = k;
    if (events_depth_ != kNone && depth() == events_depth_ + 1) member_ = std::move(k);
    expect_ = Expect::colon;
    key_end_ = offset();
    return true;
  }
  bool end_object() override {
    const bool was_event = events_depth_ != kNone && depth() == events_depth_ + 1;
    stack_.pop_back();
    if (was_event) events_.push_back(std::move(event_));
    return after_value(offset());
  }
  bool start_array(std::size_t) override {
    const bool holds_events = depth() == 0 || trace_events_value();
    if (!may_open(Container::array)) return false;
    stack_.push_back(Container::array);
    if (holds_events) {
      events_depth_ = depth();
      events_seen_ = true;
      top_level_array_ = depth() == 1;
    }
    expect_ = Expect::value_or_end;
    open_end_ = offset();
    return true;
  }
  bool end_array() override {
    if (depth() == events_depth_) events_depth_ = kNone;
    stack_.pop_back();
    return after_value(offset());
  }

  bool parse_error(std::size_t position, const std::string& last_token, const nlohmann::detail::exception& ex) override {
    // `position` counts the characters read, the end of the input included.
    error_line_ = lines_.line_of(position == 0 ? 0 : position - 1);
    if (position > text_.size()) {
      error_ = truncated_message();
    } else if (ex.id == 406) {  // number overflow
      error_ = "number " + quote(last_token) + " is out of range";
    } else {
      // nlohmann's words without its prefix and its own, uncut, copy of the token.
      std::string what = ex.what();
      if (const std::size_t colon = what.find(": "); colon != std::string::npos) what.erase(0, colon + 2);
      if (const std::size_t dash = what.find(" - "); dash != std::string::npos) what.erase(0, dash + 3);
      if (const std::size_t lr = what.find("; last read: "); lr != std::string::npos) what.erase(lr);
      error_ = "malformed JSON: " + what;
      // nlohmann's copy of the token is only meaningful when short (at the end of the document
      // it holds everything since the last token, newlines spelled <U+000A>).
      if (!last_token.empty() && last_token.size() <= 24 && last_token.find("<U+") == std::string::npos)
        error_ += " at " + quote(last_token);
    }
    return false;
  }

 private:
  enum class Container : std::uint8_t { object, array };
  enum class Kind : std::uint8_t { string, number, other };
  /// What may come next after the last complete token the handler saw.
  enum class Expect : std::uint8_t { key_or_end, colon, value_or_end, comma_or_end, end };
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);

  std::size_t depth() const { return stack_.size(); }
  std::size_t offset() const { return static_cast<std::size_t>(cursor_ - text_.data()); }
  /// The value being read is that of the top-level "traceEvents" member.
  bool trace_events_value() const {
    return depth() == 1 && stack_[0] == Container::object && top_key_ == "traceEvents";
  }
  /// What the array of events is called in messages.
  std::string events_name() const { return top_level_array_ ? "the array of events" : "\"traceEvents\""; }
  /// The value being read is a member of an event object (member_ names it).
  bool in_event() const { return events_depth_ != kNone && depth() == events_depth_ + 1; }
  bool is_text_member() const { return member_ == "ph" || member_ == "pid" || member_ == "tid" || member_ == "name"; }

  bool fail(std::string message) {
    error_line_ = lines_.line_of(offset() == 0 ? 0 : offset() - 1);
    error_ = std::move(message);
    return false;
  }

  /// Checks a value about to be read where the trace's structure wants something else.
  bool check_place(Kind kind) {
    if (events_depth_ != kNone && depth() == events_depth_)
      return fail(events_name() + " holds something other than event objects");
    if (trace_events_value()) return fail("\"traceEvents\" must be an array of events");
    if (in_event()) {
      if (is_text_member() && kind != Kind::string) return fail("\"" + member_ + "\" must be a string");
      if (member_ == "ts" && kind != Kind::number) return fail("\"ts\" must be a number");
    }
    return true;
  }

  bool may_open(Container c) {
    if (depth() >= kMaxDepth)
      return fail("JSON nested deeper than " + std::to_string(kMaxDepth) + " levels (not a sigrok-cli trace)");
    if (c == Container::array && trace_events_value()) return true;                           // the events array
    if (c == Container::object && events_depth_ != kNone && depth() == events_depth_) return true;  // an event
    return check_place(Kind::other);
  }

  bool scalar(Kind kind, std::string value) {
    if (!check_place(kind)) return false;
    if (in_event()) {
      if (member_ == "ph") event_.ph = std::move(value);
      else if (member_ == "pid") event_.pid = std::move(value);
      else if (member_ == "tid") event_.tid = std::move(value);
      else if (member_ == "name") event_.name = std::move(value);
      else if (member_ == "ts") event_.ts = std::move(value);
    }
    // A number is known to have ended only when the lexer read the character after it.
    std::size_t end = offset();
    if (kind == Kind::number && end > 0 && std::string_view("0123456789+-.eE").find(text_[end - 1]) == std::string_view::npos)
      --end;
    return after_value(end);
  }

  bool after_value(std::size_t end) {
    last_value_end_ = end;
    expect_ = depth() == 0 ? Expect::end : Expect::comma_or_end;
    return true;
  }

  /// The message for a text that ends early, saying what was expected (as the hand-written
  /// reader before this one did).
  std::string truncated_message() const {
    auto trim = [](std::string_view s) {
      while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r' || s.front() == '\n'))
        s.remove_prefix(1);
      return s;
    };
    const std::size_t from = expect_ == Expect::colon                                         ? key_end_
                             : expect_ == Expect::key_or_end || expect_ == Expect::value_or_end ? open_end_
                                                                                              : last_value_end_;
    std::string_view rest = trim(text_.substr(std::min(from, text_.size())));
    std::string expected;
    switch (expect_) {
      case Expect::colon:
        if (rest.empty()) {
          expected = "':'";
        } else if (rest.front() == ':') {
          rest = trim(rest.substr(1));
          if (rest.empty()) expected = "a value";
        }
        break;
      case Expect::key_or_end:
        if (rest.empty()) expected = "'\"'";
        break;
      case Expect::value_or_end:
        if (rest.empty()) expected = "a value";
        break;
      case Expect::comma_or_end:
        if (rest.empty()) {
          expected = "','";
        } else if (rest.front() == ',') {
          rest = trim(rest.substr(1));
          if (rest.empty()) expected = !stack_.empty() && stack_.back() == Container::object ? "'\"'" : "a value";
        }
        break;
      case Expect::end:
        break;
    }
    if (expected.empty()) {
      // Inside a value that was cut off.
      if (!rest.empty() && rest.front() == '"') return "unterminated string (truncated file?)";
      expected = "','";
    }
    return "unexpected end of file, expected " + expected + " (truncated file?)";
  }

  std::string_view text_;
  const std::string& name_;
  const char* cursor_ = nullptr;  // how far nlohmann has read (TrackingIterator keeps it)
  LineCounter lines_;
  std::vector<JsonEvent> events_;
  std::vector<Container> stack_;
  std::size_t events_depth_ = kNone;  // depth of the array of events being read
  bool events_seen_ = false, top_level_array_ = false;
  std::string top_key_, member_;
  JsonEvent event_;
  Expect expect_ = Expect::end;
  std::size_t key_end_ = 0, last_value_end_ = 0, open_end_ = 0;
  std::string error_;
  std::uint64_t error_line_ = 0;
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
  const std::vector<JsonEvent> events = EventCollector(text, name).parse();

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
    switch (parse_source_time_checked(e.ts, -6, t)) {
      case TimeParse::ok: break;
      case TimeParse::out_of_range:
        throw TraceError(name, e.line, "\"ts\" " + quote(e.ts) + " is out of range (a time in microseconds)");
      case TimeParse::malformed:
        throw TraceError(name, e.line,
                         e.ts.empty() ? std::string("event without \"ts\"")
                                      : "\"ts\" " + quote(e.ts) + " is not a time in microseconds");
    }
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
