// sigrok-cli's JSON trace of the spi decoder (--protocol-decoder-jsontrace, Chrome trace
// format): {"traceEvents": [{"ph": "B"|"E", "ts": µs, "pid": "spi-1", "tid": "MOSI transfer",
// "name": "21 D0"}, ...]}. CS frames from the MOSI/MISO transfer annotations (the decoder
// needs a cs channel for them), else one frame per MOSI/MISO data byte. JSON is read with
// nlohmann-json's SAX parser (iterative, nesting capped) from a stream of the text (a file is
// never held whole), twice: a survey (which decoder, which annotations), then the frames, each
// event handled as it is read. Line numbers are counted as the parser reads.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <deque>
#include <functional>
#include <iterator>
#include <map>
#include <vector>

#include "spi/import_source.hpp"
#include "spi/import_support.hpp"
#include "spi/trace_import.hpp"

namespace l6470emu {
namespace {

using detail::FrameBuilder;
using detail::ImportSource;
using detail::quote;
using Json = nlohmann::json;

/// Deeper nesting than this is refused (a Chrome trace needs 4 levels; arbitrary "args" a few more).
constexpr std::size_t kMaxDepth = 512;
/// The longest stretch without a complete token (a frame's bytes written "D0 D0 ...": 3 MiB).
constexpr std::size_t kMaxToken = 4 * kMaxTraceFrameBytes;
/// What is kept of that stretch for the message about a truncated file (its start is all it needs).
constexpr std::size_t kKeptSince = 256;

/// One annotation event, the fields the spi decoder writes.
struct JsonEvent {
  std::string ph, pid, tid, name;
  std::string ts;  // the number as written
  std::uint64_t line = 0;
};

/// The text as the parser reads it, a character at a time from the source's chunks: how far it
/// has read, the line it is on, and what it read since the handler last heard of a token (for
/// the message about a truncated file). A stretch of more than kMaxToken bytes without a
/// complete token ends the input early (a gigabyte-long string, a file of blanks).
class CharStream {
 public:
  explicit CharStream(ImportSource& source) : source_(source) {}

  /// Whether the input is exhausted (reads the next chunk when the current one is).
  bool at_end() {
    while (pos_ == chunk_.size()) {
      if (done_) return true;
      try {
        if (!source_.next_chunk(chunk_)) {
          done_ = true;
          chunk_ = {};
        }
      } catch (const TraceError& e) {
        throw TraceError(source_.name(), line_, e.reason());
      }
      pos_ = 0;
    }
    return false;
  }
  char peek() const { return chunk_[pos_]; }
  void advance() {
    const char c = chunk_[pos_++];
    if (c == '\n') {
      ++line_;
      last_newline_ = offset_;
    }
    ++offset_;
    last_ = c;
    if (++since_count_ > kMaxToken) {
      too_long_ = true;
      done_ = true;  // the parser sees the end of the input, and the handler says why
      chunk_ = {};
      pos_ = 0;
      return;
    }
    if (since_.size() < kKeptSince) since_ += c;
  }

  /// Characters read.
  std::size_t offset() const { return offset_; }
  /// Line (from 1) of the character at `offset`, which is at most one behind the reading.
  std::uint64_t line_of(std::size_t offset) const {
    return offset < offset_ && have_newline() && last_newline_ >= offset ? line_ - 1 : line_;
  }
  /// The last character read.
  char last() const { return last_; }
  /// The start of what was read since the handler's last token (the character before it
  /// first), at most kKeptSince characters.
  const std::string& since() const { return since_; }
  /// Where since() begins (a character offset).
  std::size_t since_begin() const { return offset_ - since_count_; }
  /// The handler heard of a token: keep only the last character read.
  void token_seen() {
    since_.assign(1, last_);
    since_count_ = offset_ > 0 ? 1 : 0;
    if (offset_ == 0) since_.clear();
  }
  /// Whether the input was cut because a token grew past kMaxTraceLineBytes.
  bool too_long() const { return too_long_; }

 private:
  bool have_newline() const { return line_ > 1; }

  ImportSource& source_;
  std::string_view chunk_;
  std::size_t pos_ = 0;
  bool done_ = false;
  std::size_t offset_ = 0;
  std::uint64_t line_ = 1;
  std::size_t last_newline_ = 0;
  char last_ = 0;
  std::string since_;
  std::size_t since_count_ = 0;  // characters read since the last token (since_ keeps their start)
  bool too_long_ = false;
};

/// An input iterator over a CharStream for nlohmann's parser; the end iterator is a sentinel.
class StreamIterator {
 public:
  using iterator_category = std::input_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = char;

  explicit StreamIterator(CharStream* stream) : stream_(stream) {}
  char operator*() const { return stream_->peek(); }
  StreamIterator& operator++() {
    stream_->advance();
    return *this;
  }
  StreamIterator operator++(int) {
    StreamIterator old = *this;
    ++*this;
    return old;
  }
  friend bool operator==(const StreamIterator& a, const StreamIterator& b) {
    const CharStream* s = a.stream_ ? a.stream_ : b.stream_;
    if (s == nullptr) return true;
    const bool a_end = a.stream_ == nullptr || a.stream_->at_end();
    const bool b_end = b.stream_ == nullptr || b.stream_->at_end();
    return a_end && b_end;
  }
  friend bool operator!=(const StreamIterator& a, const StreamIterator& b) { return !(a == b); }

 private:
  CharStream* stream_;  // nullptr: the end
};

/// Collects the events of a Chrome trace from nlohmann's SAX callbacks. Knows where it is:
/// the containers open around it and what the parser expects next (for truncated files).
class EventCollector final : public nlohmann::json_sax<Json> {
 public:
  using Handler = std::function<void(JsonEvent&)>;
  EventCollector(ImportSource& source, Handler handler)
      : name_(source.name()), stream_(source), handler_(std::move(handler)) {}

  /// Parses the whole text, handing each event to the handler as it ends; throws TraceError
  /// naming the line of the problem (the handler's own TraceErrors pass through).
  void parse() {
    while (!stream_.at_end() &&
           (stream_.peek() == ' ' || stream_.peek() == '\t' || stream_.peek() == '\r' || stream_.peek() == '\n'))
      stream_.advance();
    if (stream_.at_end() || (stream_.peek() != '{' && stream_.peek() != '['))
      throw TraceError(name_, stream_.line_of(stream_.offset()),
                       "not JSON (expected sigrok-cli --protocol-decoder-jsontrace output, which starts with '{')");
    stream_.token_seen();
    const StreamIterator first(&stream_), last(nullptr);
    if (!Json::sax_parse(first, last, this)) {
      if (handler_error_) std::rethrow_exception(handler_error_);
      throw TraceError(name_, error_line_, error_);
    }
    if (!events_seen_)
      throw TraceError(name_, 0, "no \"traceEvents\" array (expected sigrok-cli --protocol-decoder-jsontrace output)");
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
    stream_.token_seen();
    if (!may_open(Container::object)) return false;
    stack_.push_back(Container::object);
    if (events_depth_ != kNone && depth() == events_depth_ + 1) {
      event_ = JsonEvent{};
      event_.line = stream_.line_of(offset() - 1);  // the '{' just read
    }
    expect_ = Expect::key_or_end;
    open_end_ = offset();
    return true;
  }
  bool key(string_t& k) override {
    stream_.token_seen();
    if (depth() == 1 && stack_[0] == Container::object) top_key_ = k;
    if (events_depth_ != kNone && depth() == events_depth_ + 1) member_ = std::move(k);
    expect_ = Expect::colon;
    key_end_ = offset();
    return true;
  }
  bool end_object() override {
    stream_.token_seen();
    const bool was_event = events_depth_ != kNone && depth() == events_depth_ + 1;
    stack_.pop_back();
    if (was_event) {
      try {
        handler_(event_);
      } catch (...) {
        handler_error_ = std::current_exception();
        return false;
      }
    }
    return after_value(offset());
  }
  bool start_array(std::size_t) override {
    stream_.token_seen();
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
    stream_.token_seen();
    if (depth() == events_depth_) events_depth_ = kNone;
    stack_.pop_back();
    return after_value(offset());
  }

  bool parse_error(std::size_t position, const std::string& last_token, const nlohmann::detail::exception& ex) override {
    if (handler_error_) return false;
    // `position` counts the characters read, the end of the input included.
    error_line_ = stream_.line_of(position == 0 ? 0 : position - 1);
    if (stream_.too_long()) {
      error_ = "more than " + std::to_string(kMaxToken) + " bytes without a complete JSON token (a frame holds at most " +
               std::to_string(kMaxTraceFrameBytes) + " bytes: not a sigrok-cli trace, or a damaged one)";
    } else if (position > stream_.offset()) {
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
  std::size_t offset() const { return stream_.offset(); }
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
    error_line_ = stream_.line_of(offset() == 0 ? 0 : offset() - 1);
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
    stream_.token_seen();
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
    if (kind == Kind::number && end > 0 && std::string_view("0123456789+-.eE").find(stream_.last()) == std::string_view::npos)
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
    // What was read since the handler's last token (the character before it included).
    const std::string& since = stream_.since();
    const std::size_t since_begin = stream_.since_begin();
    std::string_view rest = trim(std::string_view(since).substr(std::min(from > since_begin ? from - since_begin : 0, since.size())));
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

  const std::string& name_;
  CharStream stream_;
  Handler handler_;
  std::exception_ptr handler_error_;
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
    if (out.size() >= kMaxTraceFrameBytes) throw TraceError(name, e.line, frame_too_long(out.size() + 1));
    out.push_back(static_cast<std::uint8_t>(hex_digit_value(tok[0]) << 4 | hex_digit_value(tok[1])));
    s.remove_prefix(n);
  }
}

bool starts_with(const std::string& s, std::string_view prefix) { return s.rfind(prefix, 0) == 0; }

/// The first pass: which decoder instance, and whether it made transfer annotations.
struct Survey {
  std::string pid;             // the decoder instance taken
  bool transfers = false;      // it has MOSI/MISO transfer annotations
  std::uint64_t conflict_line = 0;  // a second decoder's annotation (without --select)
  std::string conflict_pid;

  void look_at(const JsonEvent& e, const ImportOptions& options) {
    if (!starts_with(e.tid, "MOSI") && !starts_with(e.tid, "MISO")) return;
    if (options.select.empty()) {
      if (pid.empty()) pid = e.pid;
      else if (e.pid != pid && conflict_line == 0) {
        conflict_line = e.line;
        conflict_pid = e.pid;
      }
    }
    const std::string& taken = options.select.empty() ? pid : options.select;
    if (e.pid == taken && (e.tid == "MOSI transfer" || e.tid == "MISO transfer")) transfers = true;
  }
};

/// The second pass: B/E pairs per track become spans, MOSI spans are matched with the MISO span
/// that begins with them (the decoder emits both for each frame, in time order), and frames go
/// to the trace as soon as their partner is known.
class FrameMaker {
 public:
  FrameMaker(Trace& trace, const std::string& name, const ImportOptions& options, const Survey& survey)
      : trace_(trace), name_(name), frames_(trace, name, options.max_frames),
        pid_(options.select.empty() ? survey.pid : options.select),
        mosi_tid_(survey.transfers ? "MOSI transfer" : "MOSI data"),
        miso_tid_(survey.transfers ? "MISO transfer" : "MISO data") {}

  void event(const JsonEvent& e) {
    if (e.pid != pid_ || (e.tid != mosi_tid_ && e.tid != miso_tid_)) return;
    const bool is_mosi = e.tid == mosi_tid_;
    const char* what = is_mosi ? "MOSI" : "MISO";
    SourceTime t;
    switch (parse_source_time_checked(e.ts, -6, t)) {
      case TimeParse::ok: break;
      case TimeParse::out_of_range:
        throw TraceError(name_, e.line, "\"ts\" " + quote(e.ts) + " is out of range (a time in microseconds)");
      case TimeParse::malformed:
        throw TraceError(name_, e.line,
                         e.ts.empty() ? std::string("event without \"ts\"")
                                      : "\"ts\" " + quote(e.ts) + " is not a time in microseconds");
    }
    Track& track = is_mosi ? mosi_track_ : miso_track_;
    if (e.ph == "B") {
      if (track.open) throw TraceError(name_, e.line, std::string(what) + " annotation begins while the one of line " +
                                                         std::to_string(track.span.line) + " is still open");
      track.open = true;
      track.span = Span{};
      track.span.begin = t;
      track.span.line = e.line;
      parse_bytes(name_, e, what, track.span.bytes);
    } else if (e.ph == "E") {
      if (!track.open) throw TraceError(name_, e.line, std::string(what) + " annotation ends without a begin");
      if (t < track.span.begin) throw TraceError(name_, e.line, "time goes backwards: the annotation ends before it begins");
      track.span.end = t;
      track.open = false;
      if (is_mosi) {
        ++mosi_count_;
        mosi_.push_back(std::move(track.span));
      } else {
        ++miso_count_;
        miso_.push_back(std::move(track.span));
      }
      match(false);
    } else {
      throw TraceError(name_, e.line, "\"ph\" " + quote(e.ph) + " is neither B nor E");
    }
  }

  /// The end of the events: what is still open or unmatched, and the notes.
  void finish(bool transfers) {
    for (const Track* track : {&mosi_track_, &miso_track_})
      if (track->open)
        throw TraceError(name_, track->span.line,
                         (track == &mosi_track_ ? mosi_tid_ : miso_tid_) + " annotation never ends (truncated file?)");
    if (mosi_count_ == 0) {
      if (miso_count_ > 0)
        throw TraceError(name_, miso_.front().line, "MISO annotations but no MOSI: give the spi decoder a mosi channel");
      throw TraceError(name_, 0, "no spi decoder annotations (run sigrok-cli -P spi:...:cs=CS --protocol-decoder-jsontrace)");
    }
    match(true);
    if (!transfers)
      trace_.header.notes.push_back(
          "no MOSI/MISO transfer annotations (the decoder had no cs channel): each byte is taken as its own CS frame");
    if (miso_count_ == 0) trace_.header.notes.push_back("no MISO annotations: MISO bytes are unknown and not compared");
  }

 private:
  /// An annotation from its B to its E event.
  struct Span {
    SourceTime begin, end;
    std::vector<std::uint8_t> bytes;
    std::uint64_t line = 0;
  };
  struct Track {
    bool open = false;
    Span span;
  };

  /// Frames for the MOSI spans whose MISO partner (or its absence) is known; `all` at the end.
  void match(bool all) {
    while (!mosi_.empty()) {
      const Span& m = mosi_.front();
      if (miso_.empty() && !all) return;  // its partner may still come
      if (!miso_.empty() && miso_.front().begin < m.begin)
        throw TraceError(name_, miso_.front().line, "MISO annotation at " + FrameBuilder::seconds(miso_.front().begin) +
                                                        " s has no MOSI annotation beside it");
      const Span* r = !miso_.empty() && miso_.front().begin == m.begin ? &miso_.front() : nullptr;
      if (r != nullptr && r->bytes.size() != m.bytes.size())
        throw TraceError(name_, r->line, "MOSI has " + std::to_string(m.bytes.size()) + " bytes but MISO has " +
                                             std::to_string(r->bytes.size()) + " in the frame at " +
                                             FrameBuilder::seconds(m.begin) + " s");
      const std::span<const std::uint8_t> rx = r != nullptr ? std::span<const std::uint8_t>(r->bytes)
                                                            : std::span<const std::uint8_t>{};
      frames_.frame(m.begin, std::max(m.end, r != nullptr ? r->end : m.end), m.bytes, rx, {}, m.line);
      if (r != nullptr) miso_.pop_front();
      mosi_.pop_front();
    }
  }

  Trace& trace_;
  const std::string& name_;
  FrameBuilder frames_;
  std::string pid_, mosi_tid_, miso_tid_;
  Track mosi_track_, miso_track_;
  std::deque<Span> mosi_, miso_;  // complete spans not yet made frames
  std::uint64_t mosi_count_ = 0, miso_count_ = 0;
};

}  // namespace

Trace detail::import_sigrok(ImportSource& source, const ImportOptions& options) {
  const std::string& name = source.name();
  Trace trace;
  trace.header.name = name;
  trace.header.format = "sigrok";
  // First pass: the whole JSON checked, the decoder instance chosen.
  Survey survey;
  EventCollector(source, [&](JsonEvent& e) { survey.look_at(e, options); }).parse();
  if (survey.conflict_line != 0)
    throw TraceError(name, survey.conflict_line, "annotations of several spi decoders (" + quote(survey.pid) + " and " +
                                                     quote(survey.conflict_pid) + "): choose one with --select");
  // Second pass: the frames.
  source.rewind();
  FrameMaker maker(trace, name, options, survey);
  EventCollector(source, [&](JsonEvent& e) { maker.event(e); }).parse();
  maker.finish(survey.transfers);
  return trace;
}

}  // namespace l6470emu
