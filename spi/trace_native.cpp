// Native trace format, versions 1 to 3: parsing line by line with exact times and expanding
// `repeat` lines, and writing with one flush per event and runs of repeated frames
// collapsed. The grammar is in docs/trace-format.md.
#include "spi/trace_native.hpp"
#include "core/axis_text.hpp"
#include "core/counted.hpp"

#include "spi/import_support.hpp"
#include "spi/trace_file.hpp"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace l6470emu {
namespace {

constexpr std::size_t kChunk = 1 << 20;

bool is_space(char c) { return c == ' ' || c == '\t'; }

using detail::next_token;

std::string quoted(std::string_view s) { return detail::quote(s); }

/// Whether a first word that is not a time was meant as one ("-1", ".5", "nan", "inf").
bool looks_like_a_time(std::string_view w) {
  if (w[0] == '-' || w[0] == '+' || w[0] == '.') return true;
  std::string lower;
  for (char c : w.substr(0, 9)) lower += static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  return lower == "nan" || lower == "inf" || lower == "infinity";
}

/// A time as the file wrote it (digits and a point, already checked), or as ticks when that is long.
std::string as_written(std::string_view tok, Tick tick) {
  return tok.size() <= detail::kQuoteMax ? std::string(tok) : format_seconds(tick);
}

std::string bad_time(std::string_view tok) {
  return "bad timestamp " + quoted(tok) + " (seconds from 0, e.g. 0.00100300)";
}

/// A duration or period in µs as the writer prints it (any decimal parse_source_time takes), in
/// ticks rounded to nearest; false when malformed, negative or beyond kMaxNativeTraceTick.
bool parse_native_us(std::string_view text, Tick& out) {
  SourceTime t;
  if (!parse_source_time(text, -6, t) || t.seconds < 0 ||
      static_cast<std::uint64_t>(t.seconds) > kMaxNativeTraceSeconds)
    return false;
  const Tick ticks = static_cast<Tick>(t.seconds) * kTicksPerSecond + static_cast<Tick>((t.picoseconds + 125'000) / 250'000);
  if (ticks > kMaxNativeTraceTick) return false;
  out = ticks;
  return true;
}

/// "10^12 s" for messages.
std::string max_time_words() { return "10^" + std::to_string(std::to_string(kMaxNativeTraceSeconds).size() - 1) + " s"; }

bool parse_uint(std::string_view s, unsigned long max, unsigned long& out) {
  if (s.empty() || s.size() > 19) return false;  // 19 digits never overflow 64 bits
  unsigned long v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + static_cast<unsigned long>(c - '0');
  }
  if (v > max) return false;
  out = v;
  return true;
}

}  // namespace

// ---------------------------------------------------------------- reader

NativeTraceReader::NativeTraceReader(const std::string& path, std::uint64_t max_frames) : max_frames_(max_frames) {
  header_.name = path;
  header_.format = "native";
  file_ = std::make_unique<TraceFileReader>(path);
  // A small file gets a small buffer (it grows for a line longer than the buffer).
  const std::uint64_t size = file_->size_on_disk();
  buffer_.resize(size > 0 && !file_->gzip() ? std::clamp<std::size_t>(static_cast<std::size_t>(size) + 1, 4096, kChunk)
                                            : kChunk);
  read_header();  // a throw here closes the file (file_ is a member already constructed)
}

NativeTraceReader::NativeTraceReader(std::string_view text, std::string name, std::uint64_t max_frames)
    : text_(text), max_frames_(max_frames) {
  header_.name = std::move(name);
  header_.format = "native";
  eof_ = true;
  read_header();
}

NativeTraceReader::~NativeTraceReader() = default;

ReadProgress NativeTraceReader::progress() const {
  if (!file_) return {};
  return {file_->disk_offset(), file_->size_on_disk()};
}

void NativeTraceReader::fail(const std::string& message) const {
  std::string m = message;
  if (last_line_unterminated_) m += " (the last line has no newline: truncated file?)";
  throw TraceError(header_.name, line_no_, m);
}

bool NativeTraceReader::next_line(std::string_view& line) {
  for (;;) {
    // A line that starts with a NUL byte ends the trace: what follows is the unwritten rest of
    // a recording file that was not closed (a killed recorder's mapped file) or bytes it hid.
    if (!text_.empty() && text_[0] == '\0') {
      text_ = {};
      eof_ = true;
      return false;
    }
    const std::size_t nl = text_.find('\n');
    if (nl != std::string_view::npos) {
      line = text_.substr(0, nl);
      text_.remove_prefix(nl + 1);
      ++line_no_;
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      return true;
    }
    if (text_.size() > kMaxTraceLineBytes) {  // a line that never ends (a binary file, a gzip bomb)
      ++line_no_;
      fail(line_too_long());
    }
    if (eof_) {
      if (text_.empty()) return false;
      line = text_;
      text_ = {};
      ++line_no_;
      last_line_unterminated_ = true;
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      return true;
    }
    // File mode: move the partial line to the front and read more.
    const std::size_t keep = text_.size();
    if (keep > 0 && text_.data() != buffer_.data()) std::memmove(buffer_.data(), text_.data(), keep);
    if (keep == buffer_.size()) buffer_.resize(std::min(buffer_.size() * 2, kMaxTraceLineBytes + 2));
    std::size_t got = 0;
    try {
      got = file_->read(buffer_.data() + keep, buffer_.size() - keep);
    } catch (const TraceError& e) {
      // Every complete line before the damage has been read: say where it stopped.
      throw TraceError(header_.name, line_no_ + 1, e.reason());
    }
    if (got == 0) eof_ = true;
    text_ = std::string_view(buffer_.data(), keep + got);
  }
}

void NativeTraceReader::read_header() {
  std::string_view line;
  if (!next_line(line))
    throw TraceError(header_.name, 0,
                     "empty file (expected a native trace: 'l6470emu-trace " + std::to_string(kNativeTraceVersion) + "')");
  std::string_view rest = line;
  const std::string_view magic = next_token(rest);
  const std::string_view version = next_token(rest);
  if (magic != kNativeTraceMagic)
    fail("not an l6470emu trace: the first line must be 'l6470emu-trace " + std::to_string(kNativeTraceVersion) + "'");
  unsigned long v = 0;
  if (!parse_uint(version, 1000000, v) || !next_token(rest).empty()) fail("malformed header line " + quoted(line));
  if (v < 1 || v > static_cast<unsigned long>(kNativeTraceVersion))
    fail("format version " + std::to_string(v) + " (this l6470emu reads versions 1 to " +
         std::to_string(kNativeTraceVersion) + ")");
  header_.version = static_cast<int>(v);
  // Directives up to the first event.
  while (next_line(line)) {
    rest = line;
    const std::string_view word = next_token(rest);
    if (word.empty() || word[0] == '#') continue;
    if (word == "chain" || word == "board") {
      // The value without the blanks around it (a carriage return among them: the line's own
      // was taken off, and one more would not survive being written and read again).
      const auto blank = [](char c) { return is_space(c) || c == '\r'; };
      std::size_t i = 0;
      while (i < rest.size() && blank(rest[i])) ++i;
      std::string_view value = rest.substr(i);
      while (!value.empty() && blank(value.back())) value.remove_suffix(1);
      if (word == "chain") {
        if (!header_.chain.empty()) fail("a second 'chain' line (the first is line " + std::to_string(header_.chain_line) + ")");
        header_.chain = std::string(value);
        header_.chain_line = line_no_;
        if (header_.chain.empty()) fail("'chain' needs the chips, e.g. 'chain 3*L6470'");
        continue;
      }
      if (header_.version < 2) fail("'board' lines need format version 2 (the first line says 1)");
      if (value.empty()) fail("'board' needs a clause of the board description, e.g. 'board chips=L6470 axis.0=default'");
      if (header_.board.size() + value.size() > kMaxBoardBytes)
        fail("the 'board' lines hold more than " + std::to_string(kMaxBoardBytes) + " bytes (a board description is a few lines)");
      if (header_.board.empty()) header_.board_line = line_no_;
      header_.board += value;
      header_.board += '\n';
      continue;
    }
    have_pending_ = parse_line(line, pending_);
    if (have_pending_) return;
  }
}

bool NativeTraceReader::next(TraceEvent& e) {
  if (have_pending_) {
    have_pending_ = false;
    e = pending_;
    // The spans of pending_ point into mosi_/miso_/known_, which still hold its bytes.
    return true;
  }
  std::string_view line;
  for (;;) {
    if (repeat_done_ < repeat_count_) {
      next_repetition(e);
      return true;
    }
    if (!next_line(line)) return false;
    if (parse_line(line, e)) return true;
  }
}

void NativeTraceReader::keep_frame(const TraceEvent& e) {
  if (kept_.size() < kMaxRepeatGroup) kept_.resize(kMaxRepeatGroup);
  Kept& k = kept_[kept_next_];
  k.tick = e.tick;
  k.duration = e.duration;
  k.mosi.assign(e.mosi.begin(), e.mosi.end());
  k.miso.assign(e.miso.begin(), e.miso.end());
  k.known.assign(e.miso_known.begin(), e.miso_known.end());
  kept_next_ = (kept_next_ + 1) % kMaxRepeatGroup;
  kept_count_ = std::min(kept_count_ + 1, kMaxRepeatGroup);
}

/// The next frame a `repeat` line stands for. The ring holds the group as the last
/// repetition left it: each frame moves on by one period as it is handed out again.
void NativeTraceReader::next_repetition(TraceEvent& e) {
  const std::size_t slot = (kept_next_ + kMaxRepeatGroup - group_ + group_index_) % kMaxRepeatGroup;
  Kept& k = kept_[slot];
  k.tick += repeat_period_;
  e = TraceEvent{};
  e.kind = TraceEventKind::frame;
  e.tick = k.tick;
  e.duration = k.duration;
  e.mosi = k.mosi;
  e.miso = k.miso;
  e.miso_known = k.known;
  e.wire = wire_;  // (a `wire` line ends the frames a repeat line may repeat)
  e.line = repeat_line_;
  e.repetition = repeat_done_ + 1;
  if (++group_index_ == group_) {
    group_index_ = 0;
    ++repeat_done_;
  }
}

/// `TIME repeat K frames N times every PERIODus`: checks it and sets up the repetitions.
void NativeTraceReader::parse_repeat(std::string_view rest, std::string_view time_tok, Tick tick) {
  const std::string_view group_tok = next_token(rest), frames_tok = next_token(rest);
  std::string_view count_tok, times_tok, every_tok, period_tok;
  // Closed: `TIME repeat K frames N times every PERIODus`, TIME = the last repetition's last frame.
  // Open (version 2): `TIME repeat K frames every PERIODus times N`, TIME = the group's last
  // frame before the repetitions, N from 0 (a recording updates it in place).
  std::string_view rest_after = rest;
  const bool open = next_token(rest_after) == "every";
  if (open) {
    every_tok = next_token(rest);
    period_tok = next_token(rest);
    times_tok = next_token(rest);
    count_tok = next_token(rest);
  } else {
    count_tok = next_token(rest);
    times_tok = next_token(rest);
    every_tok = next_token(rest);
    period_tok = next_token(rest);
  }
  const std::string form = open ? " (expected 'TIME repeat K frames every PERIODus times N')"
                                : " (expected 'TIME repeat K frames N times every PERIODus')";
  if (open && header_.version < 2) fail("repeat: the form 'repeat K frames every PERIODus times N' needs format version 2");
  unsigned long group = 0;
  if (!parse_uint(group_tok, 1000000000, group) || group == 0 || group > kMaxRepeatGroup)
    fail("repeat: group size " + quoted(group_tok) + " is not a number of frames from 1 to " +
         std::to_string(kMaxRepeatGroup) + form);
  if (frames_tok != "frames" && frames_tok != "frame") fail("repeat: " + quoted(frames_tok) + " where 'frames' belongs" + form);
  std::uint64_t count = 0;
  bool count_ok = !count_tok.empty() && count_tok.size() <= 13;
  for (char c : count_tok) {
    if (c < '0' || c > '9') count_ok = false;
    if (count_ok) count = count * 10 + static_cast<std::uint64_t>(c - '0');
  }
  if (!count_ok || count < (open ? 0u : 1u) || count > kMaxRepeatCount)
    fail("repeat: count " + quoted(count_tok) + " is not a number of repetitions from " + (open ? "0" : "1") +
         " to 10^12" + form);
  if (times_tok != "times" && times_tok != "time") fail("repeat: " + quoted(times_tok) + " where 'times' belongs" + form);
  if (every_tok != "every") fail("repeat: " + quoted(every_tok) + " where 'every' belongs" + form);
  Tick period = 0;
  if (period_tok.size() <= 2 || period_tok.substr(period_tok.size() - 2) != "us" ||
      !parse_native_us(period_tok.substr(0, period_tok.size() - 2), period))
    fail("repeat: period " + quoted(period_tok) + " is not a number of microseconds up to " + max_time_words() +
         " (e.g. 1000.00us)" + form);
  if (!next_token(rest).empty()) fail("too many fields in the repeat line" + form);
  if (kept_count_ < group)
    fail("repeat: there " + std::string(kept_count_ == 1 ? "is " : "are ") + std::to_string(kept_count_) +
         " frame line" + (kept_count_ == 1 ? "" : "s") + " to repeat since the last pin or fault event, not " +
         std::to_string(group));
  const Kept& first = kept_[(kept_next_ + kMaxRepeatGroup - group) % kMaxRepeatGroup];
  const Kept& last = kept_[(kept_next_ + kMaxRepeatGroup - 1) % kMaxRepeatGroup];
  if (period == 0) fail("repeat: period " + quoted(period_tok) + " is 0: repetitions take time" + form);
  if (period < last.tick + last.duration - first.tick)
    fail("repeat: period " + quoted(period_tok) + " is shorter than the " + counted(group, "frame") +
         " it repeats (" + format_microseconds(last.tick + last.duration - first.tick) + " us from the first CS "
         "falling edge to the last CS rising edge): repetitions would overlap");
  const Tick limit = kMaxNativeTraceTick - last.duration;  // the last repetition's CS rising edge fits too
  if (open) {
    // The time written is the group's last frame, before any repetition.
    if (tick != last.tick)
      fail("repeat: the line's time " + as_written(time_tok, tick) + " s is not when the group's last frame starts (" +
           format_seconds(last.tick) + " s)");
    if (count != 0 && (period > limit / count || last.tick > limit - period * count))
      fail("repeat: the last repetition would end after " + max_time_words());
  }
  // Closed: the time written is the last repeated frame's: the group's last frame, count periods on.
  else if (period > limit / count || last.tick > limit - period * count || last.tick + period * count != tick)
    fail("repeat: the line's time " + as_written(time_tok, tick) + " s is not when the last repetition's last frame starts (" +
         (period <= limit / count && last.tick <= limit - period * count ? format_seconds(last.tick + period * count) + " s"
                                                                         : "beyond " + max_time_words()) +
         ": its last frame at " + format_seconds(last.tick) + " s plus " + std::to_string(count) + " periods)");
  // The work it asks for, refused before any of it is done (10^12 frames from 160 bytes).
  if (max_frames_ != 0 && (count > (max_frames_ - std::min(frames_, max_frames_)) / group))
    fail("repeat: " + std::to_string(count) + " repetitions of " + std::to_string(group) +
         (group == 1 ? " frame" : " frames") + " make the trace " + std::to_string(frames_ + group * count) +
         " frames long: " + too_many_frames(max_frames_));
  frames_ += group * count;
  group_ = group;
  group_index_ = 0;
  repeat_count_ = count;
  repeat_done_ = 0;
  repeat_period_ = period;
  repeat_line_ = line_no_;
  last_frame_end_ = last.tick + period * count + last.duration;
}

/// Parses one line into `e`; false for comments and blank lines.
bool NativeTraceReader::parse_line(std::string_view line, TraceEvent& e) {
  std::string_view rest = line;
  const std::string_view time_tok = next_token(rest);
  if (time_tok.empty() || time_tok[0] == '#') return false;
  if (time_tok[0] < '0' || time_tok[0] > '9') {
    if (time_tok == "chain" || time_tok == "board") fail("'" + std::string(time_tok) + "' must come before the first event");
    if (looks_like_a_time(time_tok)) fail(bad_time(time_tok));
    fail("unknown line " + quoted(line) + " (expected '<time> frame|repeat|pin|fault|load|advance|axis|stops|supply|wire ...')");
  }

  // Time: seconds, decimal (the writer uses 8 decimals: exact ticks).
  Tick tick = 0;
  {
    std::uint64_t whole = 0;
    std::size_t i = 0;
    for (; i < time_tok.size() && time_tok[i] >= '0' && time_tok[i] <= '9'; ++i) {
      whole = whole * 10 + static_cast<std::uint64_t>(time_tok[i] - '0');
      if (whole > kMaxNativeTraceSeconds)
        fail("timestamp " + quoted(time_tok) + " is too large (at most " + max_time_words() + ")");
    }
    std::uint64_t frac_ticks = 0;
    if (i < time_tok.size() && time_tok[i] == '.') {
      ++i;
      // Up to 12 digits of fraction in ps, rounded to a tick.
      std::uint64_t ps = 0;
      std::uint64_t scale = 100'000'000'000ull;
      bool round_up = false;
      std::size_t digits = 0;
      for (; i < time_tok.size() && time_tok[i] >= '0' && time_tok[i] <= '9'; ++i, ++digits) {
        const auto d = static_cast<std::uint64_t>(time_tok[i] - '0');
        if (digits < 12) {
          ps += d * scale;
          scale /= 10;
        } else if (digits == 12) {
          round_up = d >= 5;
        }
      }
      if (digits == 0) fail(bad_time(time_tok));
      ps += round_up ? 1 : 0;
      frac_ticks = (ps + 125'000) / 250'000;
    }
    if (i != time_tok.size()) fail(bad_time(time_tok));
    tick = whole * kTicksPerSecond + frac_ticks;
    if (tick > kMaxNativeTraceTick)
      fail("timestamp " + quoted(time_tok) + " is too large (at most " + max_time_words() + ")");
  }
  if (any_event_ && tick < last_tick_)
    fail("time " + as_written(time_tok, tick) + " s goes backwards (the previous event was at " + format_seconds(last_tick_) +
         " s)");

  const std::string_view kind = next_token(rest);
  if (kind == "wire") {
    // Version 3: the host's settings for the frames from here on. Not an event of its own: the
    // frames carry it (TraceEvent::wire).
    if (header_.version < 3)
      fail("'wire' lines need format version 3 (the first line says " + std::to_string(header_.version) + ")");
    const std::string why = parse_wire_fields(rest, wire_);
    if (!why.empty()) fail(why + " (expected " + std::string(kWireLineForm) + ")");
    kept_count_ = 0;  // a repeat line repeats the frames after it only
    any_event_ = true;
    last_tick_ = tick;
    return false;
  }
  if (kind == "repeat") {
    parse_repeat(rest, time_tok, tick);
    // Later events come after the last repetition (an open line's time is its group's).
    last_tick_ = std::max(tick, last_frame_end_ - kept_[(kept_next_ + kMaxRepeatGroup - 1) % kMaxRepeatGroup].duration);
    return false;  // next() hands out the repetitions
  }
  e = TraceEvent{};
  e.tick = tick;
  e.line = line_no_;
  if (kind == "frame") {
    e.kind = TraceEventKind::frame;
    if (tick < last_frame_end_)
      fail("frame at " + as_written(time_tok, tick) + " s starts before the previous frame ended (" +
           format_seconds(last_frame_end_) + " s)");
    mosi_.clear();
    miso_.clear();
    known_.clear();
    bool in_miso = false, any_unknown = false;
    for (;;) {
      const std::string_view tok = next_token(rest);
      if (tok.empty()) break;
      if (tok == "|") {
        if (in_miso) fail("a second '|' in the frame");
        in_miso = true;
        continue;
      }
      if (!in_miso && mosi_.empty() && tok.size() > 2 && tok.substr(tok.size() - 2) == "us") {
        // Duration in µs, 2 decimals (exact ticks); rounded to a tick otherwise.
        SourceTime d;
        if (!parse_source_time(tok.substr(0, tok.size() - 2), -6, d) || d.seconds < 0)
          fail("frame duration " + quoted(tok) + " is not a number of microseconds");
        Tick ticks = 0;
        if (!parse_native_us(tok.substr(0, tok.size() - 2), ticks))
          fail("frame duration " + quoted(tok) + " is too long (at most " + max_time_words() + ")");
        if (e.duration != 0) fail("a second frame duration " + quoted(tok));
        e.duration = ticks;
        continue;
      }
      if (tok.size() == 2) {
        const int hi = hex_digit_value(tok[0]), lo = hex_digit_value(tok[1]);
        if (hi >= 0 && lo >= 0) {
          const auto b = static_cast<std::uint8_t>(hi << 4 | lo);
          if (in_miso) {
            miso_.push_back(b);
            known_.push_back(1);
          } else {
            mosi_.push_back(b);
          }
          continue;
        }
        if (in_miso && tok == "??") {
          miso_.push_back(0);
          known_.push_back(0);
          any_unknown = true;
          continue;
        }
      }
      fail(std::string(in_miso ? "MISO " : "MOSI ") + quoted(tok) + " is not a byte (two hex digits" +
           (in_miso ? ", or ?? for unknown)" : ")"));
    }
    if (mosi_.size() > kMaxTraceFrameBytes) fail(frame_too_long(mosi_.size()));
    if (max_frames_ != 0 && frames_ >= max_frames_) fail("the trace holds " + too_many_frames(max_frames_));
    ++frames_;
    if (in_miso && miso_.size() != mosi_.size())
      fail("frame has " + counted(mosi_.size(), "MOSI byte") + " but " + counted(miso_.size(), "MISO byte"));
    e.mosi = mosi_;
    if (in_miso) e.miso = miso_;
    if (any_unknown) e.miso_known = known_;
    e.wire = wire_;
    if (e.duration > kMaxNativeTraceTick - tick)
      fail("frame at " + as_written(time_tok, tick) + " s ends after " + max_time_words() +
           " (the latest time a native trace holds)");
    last_frame_end_ = e.end();
    keep_frame(e);
  } else if (kind == "pin" || kind == "fault") {
    kept_count_ = 0;  // a repeat line repeats frames only, with nothing between them
    const std::string_view chip_tok = next_token(rest);
    const std::string_view name = next_token(rest);
    const std::string_view value = next_token(rest);
    unsigned long chip = 0;
    if (!parse_uint(chip_tok, 255, chip)) fail("chip " + quoted(chip_tok) + " is not a chip number (0..255)");
    e.chip = static_cast<std::uint16_t>(chip);
    const std::string_view source = kind == "pin" ? next_token(rest) : std::string_view{};
    if (!next_token(rest).empty()) fail("too many fields in " + quoted(line));
    if (kind == "pin") {
      e.kind = TraceEventKind::pin;
      bool found = false;
      for (TracePin p : {TracePin::SW, TracePin::STCK, TracePin::STBY, TracePin::BUSY, TracePin::FLAG, TracePin::DIR})
        if (name == to_string(p)) {
          e.pin = p;
          found = true;
        }
      if (!found) fail("unknown pin " + quoted(name) + " (SW, STCK, STBY, BUSY, FLAG or DIR)");
      if (value != "0" && value != "1") fail("pin level " + quoted(value) + " is not 0 or 1");
      e.value = value == "1";
      // `pin K SW L axis`: the level the chip's axis drove SW to, an observation.
      if (e.pin == TracePin::SW && source == "axis") e.pin = TracePin::SW_AXIS;
      else if (!source.empty()) fail("too many fields in " + quoted(line) + (e.pin == TracePin::SW ? " (an SW the axis drove ends in 'axis')" : ""));
    } else {
      e.kind = TraceEventKind::fault;
      bool found = false;
      for (unsigned f = 0; f < kTraceFaultCount; ++f)
        if (name == to_string(static_cast<TraceFault>(f))) {
          e.fault = static_cast<TraceFault>(f);
          found = true;
        }
      if (!found)
        fail("unknown fault " + quoted(name) +
             " (UVLO, UVLO_ADC, OCD, STALL_A, STALL_B, THERMAL, ADCIN, POWER_CYCLE, MISO_FLIP or LOST_FRAME)");
      if (e.fault == TraceFault::POWER_CYCLE || e.fault == TraceFault::LOST_FRAME) {
        // One-shot: the line ends with the name.
        if (!value.empty()) fail("too many fields in " + quoted(line) + " (" + std::string(name) + " takes no value)");
        e.value = 0;
      } else if (e.fault == TraceFault::MISO_FLIP) {
        unsigned long bit = 0;
        if (!parse_uint(value, 7, bit)) fail("MISO_FLIP " + quoted(value) + " is not a bit number (0..7)");
        e.value = static_cast<std::uint8_t>(bit);
      } else if (e.fault == TraceFault::THERMAL) {
        found = false;
        for (std::uint8_t t = 0; t < 4; ++t)
          if (value == thermal_name(t)) {
            e.value = t;
            found = true;
          }
        if (!found) fail("THERMAL " + quoted(value) + " is not normal, warning, bridge_shutdown or device_shutdown");
      } else if (e.fault == TraceFault::ADCIN) {
        unsigned long code = 0;
        if (!parse_uint(value, 31, code)) fail("ADCIN " + quoted(value) + " is not an ADC code (0..31)");
        e.value = static_cast<std::uint8_t>(code);
      } else {
        if (value != "on" && value != "off") fail(std::string(name) + " " + quoted(value) + " is not on or off");
        e.value = value == "on";
      }
    }
  } else if (kind == "load" || kind == "advance") {
    if (header_.version < 2) fail("'" + std::string(kind) + "' events need format version 2 (the first line says 1)");
    kept_count_ = 0;
    if (kind == "advance") {
      e.kind = TraceEventKind::advance;
      if (!next_token(rest).empty()) fail("too many fields in " + quoted(line) + " (expected 'TIME advance')");
    } else {
      e.kind = TraceEventKind::load;
      const std::string form = " (expected 'TIME load CHIP inertia=G_MM2 friction=UNM force=UNM')";
      const std::string_view chip_tok = next_token(rest);
      unsigned long chip = 0;
      if (!parse_uint(chip_tok, 255, chip)) fail("chip " + quoted(chip_tok) + " is not a chip number (0..255)" + form);
      e.chip = static_cast<std::uint16_t>(chip);
      static constexpr std::string_view kNames[] = {"inertia=", "friction=", "force="};
      for (int i = 0; i < 3; ++i) {
        const std::string_view tok = next_token(rest);
        if (tok.substr(0, kNames[i].size()) != kNames[i]) fail("load: " + quoted(tok) + " where " + std::string(kNames[i]) + "... belongs" + form);
        std::string_view num = tok.substr(kNames[i].size());
        const bool negative = i == 2 && !num.empty() && num[0] == '-';
        if (negative) num.remove_prefix(1);
        unsigned long v = 0;
        if (!parse_uint(num, 1'000'000'000, v))
          fail("load: " + quoted(tok) + " is not a whole number from " + (i == 2 ? "-" : "") + "0 to 1000000000" + form);
        if (i == 0) e.load.inertia_g_mm2 = static_cast<std::uint32_t>(v);
        if (i == 1) e.load.friction_uNm = static_cast<std::uint32_t>(v);
        if (i == 2) e.load.force_uNm = negative ? -static_cast<std::int32_t>(v) : static_cast<std::int32_t>(v);
      }
      if (!next_token(rest).empty()) fail("too many fields in " + quoted(line) + form);
    }
  } else if (kind == "axis" || kind == "stops" || kind == "supply") {
    if (header_.version < 2) fail("'" + std::string(kind) + "' events need format version 2 (the first line says 1)");
    kept_count_ = 0;
    const std::string form = kind == "axis"    ? " (expected 'TIME axis CHIP SPEC' or 'TIME axis CHIP none')"
                             : kind == "stops" ? " (expected 'TIME stops CHIP LOWER..UPPER', either side may be empty)"
                                               : " (expected 'TIME supply CHIP MILLIVOLTS')";
    const std::string_view chip_tok = next_token(rest);
    unsigned long chip = 0;
    if (!parse_uint(chip_tok, 255, chip)) fail("chip " + quoted(chip_tok) + " is not a chip number (0..255)" + form);
    e.chip = static_cast<std::uint16_t>(chip);
    if (kind == "axis") {
      e.kind = TraceEventKind::axis;
      std::string_view spec = rest;
      while (!spec.empty() && (spec.front() == ' ' || spec.front() == '\t')) spec.remove_prefix(1);
      while (!spec.empty() && (spec.back() == ' ' || spec.back() == '\t' || spec.back() == '\r')) spec.remove_suffix(1);
      if (spec.empty()) fail("axis without a spec" + form);
      if (spec != "none" && spec != "default") {
        AxisSpec parsed;
        const std::string why = parse_axis_spec(spec, parsed);
        if (!why.empty()) fail("axis " + quoted(spec) + ": " + why);
      }
      axis_text_.assign(spec);
      e.text = axis_text_;
    } else if (kind == "stops") {
      e.kind = TraceEventKind::stops;
      const std::string_view range = next_token(rest);
      const std::size_t dots = range.find("..");
      if (dots == std::string_view::npos) fail("stops " + quoted(range) + " is not LOWER..UPPER" + form);
      auto side = [&](std::string_view v, bool& has, std::int64_t& at) {
        has = !v.empty();
        if (!has) return;
        const bool negative = v[0] == '-';
        if (negative) v.remove_prefix(1);
        unsigned long n = 0;
        if (!parse_uint(v, 1'000'000'000'000ul, n))
          fail("stops " + quoted(range) + ": a side is not a whole number from -10^12 to 10^12 (1/128 step)" + form);
        at = negative ? -static_cast<std::int64_t>(n) : static_cast<std::int64_t>(n);
      };
      side(range.substr(0, dots), e.has_lower_stop, e.lower_stop);
      side(range.substr(dots + 2), e.has_upper_stop, e.upper_stop);
      if (e.has_lower_stop && e.has_upper_stop && e.lower_stop > e.upper_stop)
        fail("stops " + quoted(range) + ": the lower stop is above the upper one" + form);
      if (!next_token(rest).empty()) fail("too many fields in " + quoted(line) + form);
    } else {
      e.kind = TraceEventKind::supply;
      const std::string_view mv = next_token(rest);
      unsigned long v = 0;
      if (!parse_uint(mv, 1'000'000, v)) fail("supply " + quoted(mv) + " is not a whole number of millivolts (0..1000000)" + form);
      e.supply_mV = static_cast<std::uint32_t>(v);
      if (!next_token(rest).empty()) fail("too many fields in " + quoted(line) + form);
    }
  } else if (kind.empty()) {
    fail("time without an event");
  } else {
    fail("unknown event " + quoted(kind) + " (frame, repeat, pin, fault, load, advance, axis, stops, supply or wire)");
  }
  any_event_ = true;
  last_tick_ = tick;
  return true;
}

// ---------------------------------------------------------------- writer

namespace {

constexpr std::uint64_t kCheckpointRepetitions = 1024;  // gzip/stream: a run in progress is written this often...
constexpr Tick kCheckpointTicks = kTicksPerSecond;      // ...or after this much trace time

/// Whether the n bytes at a and b are equal (a frame's few bytes: a loop, not a call to memcmp).
bool same_small(const std::uint8_t* a, const std::uint8_t* b, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i)
    if (a[i] != b[i]) return false;
  return true;
}

}  // namespace

void NativeTraceWriter::Held::assign(const TraceEvent& e) {
  tick = e.tick;
  duration = e.duration;
  has_miso = !e.miso.empty();
  mosi.assign(e.mosi.begin(), e.mosi.end());
  miso.assign(e.miso.begin(), e.miso.end());
  known.assign(e.miso_known.begin(), e.miso_known.end());
  // FNV-1a over what same_bytes compares (a MISO byte not known counts as 0).
  std::uint64_t h = 0xcbf29ce484222325ull;
  auto mix = [&h](std::uint64_t v) { h = (h ^ v) * 0x100000001b3ull; };
  mix(duration);
  mix(has_miso);
  mix(mosi.size());
  for (std::uint8_t b : mosi) mix(b);
  mix(known.size());
  for (std::size_t i = 0; i < miso.size(); ++i) mix(known.empty() || known[i] ? miso[i] + 1u : 0u);
  print = h;
}

bool NativeTraceWriter::Held::same_bytes(const Held& o) const {
  // "??" bytes are written whatever their value: compare what the line shows.
  if (print != o.print || duration != o.duration || has_miso != o.has_miso || mosi != o.mosi || known != o.known) return false;
  if (miso.size() != o.miso.size()) return false;
  for (std::size_t i = 0; i < miso.size(); ++i)
    if ((known.empty() || known[i]) && miso[i] != o.miso[i]) return false;
  return true;
}

[[gnu::always_inline]] inline bool NativeTraceWriter::Held::same_bytes(const TraceEvent& e) const {
  // As same_bytes(Held) with `e` held (without copying it). Sizes first, then the few bytes.
  const std::size_t n = mosi.size();
  if (duration != e.duration || n != e.mosi.size() || miso.size() != e.miso.size() || known.size() != e.miso_known.size())
    return false;
  if (known.empty() && miso.size() == n) {
    // The usual frame, every MISO byte known: both directions in one loop.
    const std::uint8_t *m = mosi.data(), *em = e.mosi.data(), *s = miso.data(), *es = e.miso.data();
    for (std::size_t i = 0; i < n; ++i)
      if (m[i] != em[i] || s[i] != es[i]) return false;
    return true;
  }
  if (!same_small(mosi.data(), e.mosi.data(), n)) return false;
  if (known.empty()) return same_small(miso.data(), e.miso.data(), miso.size());
  if (!same_small(known.data(), e.miso_known.data(), known.size())) return false;
  for (std::size_t i = 0; i < miso.size(); ++i)
    if (known[i] && miso[i] != e.miso[i]) return false;
  return true;
}

TraceEvent NativeTraceWriter::Held::event() const {
  TraceEvent e;
  e.kind = TraceEventKind::frame;
  e.tick = tick;
  e.duration = duration;
  e.mosi = mosi;
  if (has_miso) e.miso = miso;
  e.miso_known = known;
  return e;
}

NativeTraceWriter::NativeTraceWriter(const std::string& path, bool flush_each_event)
    : NativeTraceWriter(path, NativeWriteOptions{flush_each_event, true}) {}

namespace {

TraceFlushPolicy policy_for(const NativeWriteOptions& o) {
  TraceFlushPolicy p;
  p.plain_every_event = o.flush_each_event;
  if (!o.flush_each_event) p.gzip_bytes = SIZE_MAX;  // only at the end
  return p;
}

}  // namespace

NativeTraceWriter::NativeTraceWriter(const std::string& path, NativeWriteOptions options)
    : NativeTraceWriter(open_trace_file_output(path, policy_for(options)), options) {}

NativeTraceWriter::NativeTraceWriter(std::ostream& out, bool flush_each_event)
    : NativeTraceWriter(out, NativeWriteOptions{flush_each_event, true}) {}

NativeTraceWriter::NativeTraceWriter(std::ostream& out, NativeWriteOptions options, std::string name)
    : NativeTraceWriter(stream_trace_output(out, std::move(name), options.flush_each_event), options) {}

NativeTraceWriter::NativeTraceWriter(std::unique_ptr<TraceOutput> output, NativeWriteOptions options)
    : out_(std::move(output)), options_(options) {
  if (!out_) throw std::invalid_argument("NativeTraceWriter: no output");
  open_runs_ = out_->rewritable() && options_.flush_each_event;
}

NativeTraceWriter::~NativeTraceWriter() {
  try {
    finish();
  } catch (...) {
  }
}

const std::string& NativeTraceWriter::name() const { return out_->name(); }

void NativeTraceWriter::finish() {
  if (finished_) return;
  finished_ = true;
  if (abandoned_) return;
  if (in_run_) end_run();
  out_->close();
}

void NativeTraceWriter::flush_if_due() {
  if (finished_ || abandoned_) return;
  // A quiet moment in a run: its repeat line goes with the flush the output is due for.
  if (in_run_ && !open_runs() && line_count_ > 0 && out_->flush_due().value_or(false)) write_repeat_line(true);
  out_->flush_if_due();
}

/// Closed lines: whether a run in progress is written now. An output with a flush policy says
/// when it will flush (a line written between flushes would only cost size); others get one
/// every kCheckpointRepetitions repetitions or kCheckpointTicks of trace time.
bool NativeTraceWriter::checkpoint_due() const {
  if (const std::optional<bool> due = out_->flush_due()) return *due;
  return line_count_ >= kCheckpointRepetitions || run_.back().tick - checkpoint_tick_ >= kCheckpointTicks;
}

void NativeTraceWriter::abandon() {
  if (abandoned_) return;
  abandoned_ = true;
  out_->abandon();
}

/// Open `repeat` lines (a count replaced in place) where the output can be rewritten and every
/// event must survive a kill; elsewhere closed lines, written when a run ends or at checkpoints.

void NativeTraceWriter::put(const std::string& text) { out_->append(text); }

void NativeTraceWriter::write_header(const TraceHeader& header) {
  if (header_written_) return;
  header_written_ = true;
  std::string text = std::string(kNativeTraceMagic) + " " + std::to_string(kNativeTraceVersion) + "\n";
  if (!header.chain.empty()) text += "chain " + header.chain + "\n";
  // The board description, a clause per line (the reader joins them again).
  std::string_view board = header.board;
  while (!board.empty()) {
    const std::size_t nl = board.find('\n');
    std::string_view clause = board.substr(0, nl);
    board = nl == std::string_view::npos ? std::string_view{} : board.substr(nl + 1);
    while (!clause.empty() && (clause.back() == ' ' || clause.back() == '\r')) clause.remove_suffix(1);
    if (clause.empty()) continue;
    text += "board ";
    text += clause;
    text += '\n';
  }
  text += "# " + std::string(kNativeTraceNumbering) + "\n";
  if (!header.name.empty() && header.format != "native")
    text += "# converted from " + header.name + (header.format.empty() ? "" : " (" + header.format + ")") + "\n";
  for (const std::string& note : header.notes) text += "# note: " + note + "\n";
  put(text);
  out_->event_end();
}

namespace {

/// The most characters write_frame_body writes for a frame of these many MOSI and MISO bytes.
constexpr std::size_t frame_body_room(std::size_t mosi, std::size_t miso) {
  return 7 + kMaxTimeChars + 2 + 3 * mosi + 3 + 3 * miso;  // " frame " TIME "us" " BYTES" " | BYTES"
}

/// A frame line after its time (" frame 1.75us D0 | 00") written at `p`; returns its end.
char* write_frame_body(char* p, const TraceEvent& e) {
  std::memcpy(p, " frame ", 7);
  p = write_microseconds(p + 7, e.duration);
  *p++ = 'u';
  *p++ = 's';
  if (!e.mosi.empty()) {
    *p++ = ' ';
    p = write_hex_bytes(p, e.mosi);
  }
  if (!e.miso.empty()) {
    *p++ = ' ';
    *p++ = '|';
    if (!e.mosi.empty()) {
      *p++ = ' ';
      p = write_hex_bytes(p, e.miso, e.miso_known);
    }
  }
  return p;
}

}  // namespace

[[gnu::noinline]] void NativeTraceWriter::write_line(const TraceEvent& e) {
  constexpr std::size_t kShortFrame = 32;
  if (e.kind == TraceEventKind::frame && e.mosi.size() <= kShortFrame && e.miso.size() <= kShortFrame) {
    // The line of a short frame, the most common one, straight from the stack.
    char buf[kMaxTimeChars + frame_body_room(kShortFrame, kShortFrame) + 1];
    char* p = write_frame_body(write_seconds(buf, e.tick), e);
    *p++ = '\n';
    out_->append(std::string_view(buf, static_cast<std::size_t>(p - buf)));
    return;
  }
  line_.clear();
  append_event(line_, e);
  line_ += '\n';
  put(line_);
}

void NativeTraceWriter::write(const TraceEvent& e) {
  if (finished_) throw std::logic_error("NativeTraceWriter::write after finish()");
  if (abandoned_) return;
  // What the reader would refuse is not written (a virtual host that slept past 10^12 s, a
  // frame longer than a reader takes).
  if (e.kind == TraceEventKind::frame && e.mosi.size() > kMaxTraceFrameBytes)
    throw std::runtime_error(name() + ": the frame at " + format_seconds(e.tick) +
                             " s cannot be written: " + frame_too_long(e.mosi.size()));
  if (e.tick > kMaxNativeTraceTick || e.duration > kMaxNativeTraceTick - e.tick)
    throw std::runtime_error(name() + ": an event at " + format_seconds(e.tick) + " s" +
                             (e.kind == TraceEventKind::frame ? " lasting " + format_microseconds(e.duration) + " us" : "") +
                             " is beyond " + max_time_words() + ", the latest time a native trace holds");
  if (!header_written_) write_header({});
  if (e.kind == TraceEventKind::frame && !e.wire.same_as(wire_)) write_wire_line(e);
  if (e.kind == TraceEventKind::frame && options_.compact) {
    frame(e);
  } else {
    if (in_run_) end_run();
    forget_recent();
    write_line(e);
  }
  out_->event_end();
}

/// `TIME wire ...` before `frame`, whose settings differ from the frames' before it: it ends a
/// run (a repeat line repeats frames with nothing between them), as any other line does.
void NativeTraceWriter::write_wire_line(const TraceEvent& frame) {
  if (in_run_) end_run();
  forget_recent();
  line_.clear();
  append_seconds(line_, frame.tick);
  append_wire_body(line_, frame.wire);
  line_ += '\n';
  put(line_);
  wire_ = frame.wire;
}

std::string NativeTraceWriter::format_repeat(Tick last_frame, std::size_t group, std::uint64_t count, Tick period) {
  return format_seconds(last_frame + period * count) + " repeat " + std::to_string(group) +
         (group == 1 ? " frame " : " frames ") + std::to_string(count) + (count == 1 ? " time" : " times") +
         " every " + format_microseconds(period) + "us";
}

namespace {

/// The count field of an open repeat line holding `count` (at most kMaxOpenRepeatCount): 6
/// characters, right-aligned, and the newline, as the bytes of a word in memory order (its 8th
/// byte 0).
std::uint64_t open_count_word(std::uint64_t count) {
  char field[8];
  for (int i = 5; i >= 0; --i) {
    field[i] = count != 0 || i == 5 ? static_cast<char>('0' + count % 10) : ' ';
    count /= 10;
  }
  field[6] = '\n';
  field[7] = '\0';
  std::uint64_t word;
  std::memcpy(&word, field, 8);
  return word;
}

/// The byte of `word` at memory offset i.
constexpr unsigned byte_shift(unsigned i) { return std::endian::native == std::endian::little ? 8 * i : 8 * (7 - i); }

/// The same word for one more (below kMaxOpenRepeatCount): the digits carried like an
/// odometer's, in a register (no division, no byte stores for a wider load to trip over).
std::uint64_t step_open_count_word(std::uint64_t word) {
  unsigned i = 5;
  while ((word >> byte_shift(i) & 0xff) == '9') {
    word ^= std::uint64_t{'9' ^ '0'} << byte_shift(i);
    --i;
  }
  const std::uint64_t digit = word >> byte_shift(i) & 0xff;
  return word ^ ((digit ^ (digit == ' ' ? '1' : digit + 1)) << byte_shift(i));
}

}  // namespace

/// A frame with compaction: either the next one of the run under way (the usual case in a poll
/// loop, inlined into write()), or a line of its own (after which it may start a run).
[[gnu::always_inline]] inline void NativeTraceWriter::frame(const TraceEvent& e) {
  if (in_run_) {
    const Held& model = run_[partial_];
    // A repeat line stands for at most kMaxRepeatCount repetitions (an open one for
    // kMaxOpenRepeatCount): a longer run starts anew.
    const std::uint64_t max_count = open_runs() ? kMaxOpenRepeatCount : kMaxRepeatCount;
    if (e.tick == model.tick + run_period_ && model.same_bytes(e) && line_count_ < max_count) {
      if (++partial_ < run_group_) {
        if (open_runs()) write_partial_line(e);
        return;
      }
      // A whole repetition more: the group moves on by one period.
      for (Held& h : run_) h.tick += run_period_;
      partial_ = 0;
      ++line_count_;
      ++run_repetitions_;
      if (open_runs()) {
        // The count and the end of its line, in the 8-byte word that also holds the first byte
        // of the frame lines after it: one store makes them the repetition's count instead.
        count_word_ = step_open_count_word(count_word_);
        out_->replace_tail(count_offset_, std::string_view(reinterpret_cast<const char*>(&count_word_), 7));
        if (line_count_ == kMaxOpenRepeatCount) end_run();
      } else if (options_.flush_each_event && checkpoint_due()) {
        write_repeat_line(true);
      }
      return;
    }
    end_run();
  }
  frame_line(e);
}

/// A frame of the repetition under way, in an open run: a killed process leaves it; the
/// repetition's count takes it in when the repetition is whole. Only its time is new.
[[gnu::noinline]] void NativeTraceWriter::write_partial_line(const TraceEvent& e) {
  const std::string& body = run_bodies_[partial_ - 1];
  char buf[kMaxTimeChars + 128];
  if (body.size() <= sizeof buf - kMaxTimeChars) {  // a short frame's line, from the stack
    char* p = write_seconds(buf, e.tick);
    std::memcpy(p, body.data(), body.size());
    out_->append(std::string_view(buf, static_cast<std::size_t>(p - buf) + body.size()));
  } else {
    line_.clear();
    append_seconds(line_, e.tick);
    line_ += body;
    put(line_);
  }
}

/// A frame outside a run: its own line, after which it may start one.
[[gnu::noinline]] void NativeTraceWriter::frame_line(const TraceEvent& e) {
  write_line(e);
  if (recent_.size() == 3 * kMaxRepeatGroup) {
    recent_[recent_first_].assign(e);  // the newest takes the oldest one's place (and buffers)
    recent_first_ = (recent_first_ + 1) % recent_.size();
  } else {
    straighten_recent();
    recent_.emplace_back().assign(e);
  }
  note_recent(recent_.size() - 1);
  look_for_run();
}

/// Whether the last frames are a group that came twice (closed lines) or three times (open
/// lines, which cost a line even when no repetition follows) with a constant period: then the
/// next ones may be its repetitions.
void NativeTraceWriter::look_for_run() {
  if (ready_ == 0) return;  // no group size has its streak (the usual case)
  const std::size_t n = recent_.size();
  const std::size_t copies = open_runs() ? 3 : 2;
  for (std::size_t k = 1; k <= kMaxRepeatGroup && copies * k <= n; ++k) {
    // The last (copies - 1) * k frames each repeat the one k before them, one period apart
    // (their prints say so; their bytes must say so too).
    if ((ready_ >> k & 1u) == 0) continue;
    const Held& first = recent(n - k);
    const Held& last = recent(n - 1);
    const Tick period = streak_period_[k];
    if (last.tick + last.duration - first.tick > period) continue;  // as the reader requires
    bool same = true;
    for (std::size_t j = n - (copies - 1) * k; j < n && same; ++j) same = recent(j).same_bytes(recent(j - k));
    if (!same) continue;
    straighten_recent();
    in_run_ = true;
    run_group_ = k;
    run_period_ = period;
    run_.assign(recent_.end() - static_cast<std::ptrdiff_t>(k), recent_.end());
    partial_ = 0;
    run_bodies_.resize(k);
    for (std::size_t j = 0; j < k; ++j) {
      run_bodies_[j].clear();
      append_event_body(run_bodies_[j], run_[j].event());
      run_bodies_[j] += '\n';
    }
    line_count_ = 0;
    run_repetitions_ = 0;
    line_base_ = run_.back().tick;
    checkpoint_tick_ = run_.back().tick;
    if (open_runs()) write_open_repeat_line();
    return;
  }
}

/// `TIME repeat K frames every PERIODus times N` with N 0 for now, laid out so that the count
/// field (6 characters) starts at a multiple of 8 bytes: the count, the newline and the first
/// byte of the next line then share one aligned 8-byte word of the output.
void NativeTraceWriter::write_open_repeat_line() {
  line_ = format_seconds(line_base_) + " repeat " + std::to_string(run_group_) + (run_group_ == 1 ? " frame" : " frames") +
          " every " + format_microseconds(run_period_) + "us times";
  const std::uint64_t start = out_->size();
  std::uint64_t field = start + line_.size() + 1;  // at least one blank before the count
  field = (field + 7) / 8 * 8;
  line_.append(static_cast<std::size_t>(field - start - line_.size()), ' ');
  count_offset_ = field;
  count_word_ = open_count_word(0);
  line_.append(reinterpret_cast<const char*>(&count_word_), 7);
  put(line_);
}

void NativeTraceWriter::write_repeat_line(bool progress_only) {
  if (line_count_ == 0) return;
  line_ = format_repeat(line_base_, run_group_, line_count_, run_period_);
  line_ += '\n';
  if (progress_only)
    out_->append_run_progress(line_);
  else
    put(line_);
  line_count_ = 0;
  line_base_ = run_.back().tick;
  checkpoint_tick_ = run_.back().tick;
}

/// Frame i of recent_, the one after the frames noted so far, moves each group size's streak on.
void NativeTraceWriter::note_recent(std::size_t i) {
  const Held& b = recent(i);
  const std::uint64_t* const prints = history_print_.data() + history_at_;
  const Tick* const ticks = history_tick_.data() + history_at_;
  // Most frames differ from the one k before them, for every k: their prints tell at once.
  std::uint32_t match = 0;
#pragma GCC unroll 16
  for (std::size_t k = 1; k <= kMaxRepeatGroup; ++k)
    match |= static_cast<std::uint32_t>(prints[k - 1] == b.print) << k;
  match &= (2u << history_size_) - 2;  // k = 1 .. history_size_
  const std::uint64_t copies = open_runs() ? 3 : 2;
  std::uint32_t live = 0, ready = 0;
  for (std::uint32_t m = match; m != 0; m &= m - 1) {
    const unsigned k = static_cast<unsigned>(std::countr_zero(m));
    const Tick d = b.tick - ticks[k - 1];
    if (d == 0) continue;
    if ((live_ >> k & 1u) != 0 && streak_period_[k] == d) {
      ++streak_[k];
    } else {
      streak_[k] = 1;
      streak_period_[k] = d;
    }
    live |= 1u << k;
    if (streak_[k] >= (copies - 1) * k) ready |= 1u << k;
  }
  live_ = live;
  ready_ = ready;
  history_at_ = (history_at_ + kMaxRepeatGroup - 1) % kMaxRepeatGroup;
  history_print_[history_at_] = history_print_[history_at_ + kMaxRepeatGroup] = b.print;
  history_tick_[history_at_] = history_tick_[history_at_ + kMaxRepeatGroup] = b.tick;
  if (history_size_ < kMaxRepeatGroup) ++history_size_;
}

/// The streaks over recent_ as it is now (after a run ended and rebuilt it).
void NativeTraceWriter::recount_recent() {
  live_ = ready_ = 0;
  history_size_ = 0;
  for (std::size_t i = 0; i < recent_.size(); ++i) note_recent(i);
}

/// No frame before the next one counts (a pin or fault line came between).
void NativeTraceWriter::forget_recent() {
  recent_.clear();
  recent_first_ = 0;
  recount_recent();
}

void NativeTraceWriter::straighten_recent() {
  if (recent_first_ == 0) return;
  std::rotate(recent_.begin(), recent_.begin() + static_cast<std::ptrdiff_t>(recent_first_), recent_.end());
  recent_first_ = 0;
}

/// The run is over: its repeat line and the frames of an unfinished repetition go to the file
/// (an open line has them already), and they are the recent frames from now on.
void NativeTraceWriter::end_run() {
  in_run_ = false;
  straighten_recent();
  // The frames of the unfinished repetition: the group's first ones, one period on.
  std::vector<Held> partial(run_.begin(), run_.begin() + static_cast<std::ptrdiff_t>(partial_));
  for (Held& h : partial) h.tick += run_period_;
  if (!open_runs()) {
    write_repeat_line();
    for (const Held& h : partial) write_line(h.event());
  }
  // The recent frames mirror a reader's ring of frame lines: the group's lines now stand for
  // the last repetition (moved on in place) and the unfinished repetition's lines follow. When
  // no repetition came (two alike frames inside a longer poll, say) the lines before the run
  // are all still there, so the longer group can still be found.
  if (run_repetitions_ == 0) {
    for (Held& h : partial) recent_.push_back(std::move(h));
    const std::size_t cap = 3 * kMaxRepeatGroup;
    if (recent_.size() > cap) recent_.erase(recent_.begin(), recent_.end() - static_cast<std::ptrdiff_t>(cap));
  } else {
    recent_ = std::move(run_);
    for (Held& h : partial) recent_.push_back(std::move(h));
  }
  run_.clear();
  partial_ = 0;
  recount_recent();
  // A new run may start right away among these frames (but not one that includes the old run's
  // group twice: that would have continued the run).
}

std::string NativeTraceWriter::format_event(const TraceEvent& e) {
  std::string s;
  append_event(s, e);
  return s;
}

void NativeTraceWriter::append_event(std::string& s, const TraceEvent& e) {
  append_seconds(s, e.tick);
  append_event_body(s, e);
}

void NativeTraceWriter::append_event_body(std::string& s, const TraceEvent& e) {
  switch (e.kind) {
    case TraceEventKind::frame: {
      const std::size_t at = s.size();
      s.resize(at + frame_body_room(e.mosi.size(), e.miso.size()));
      s.resize(static_cast<std::size_t>(write_frame_body(s.data() + at, e) - s.data()));
      break;
    }
    case TraceEventKind::pin:
      s += " pin " + std::to_string(e.chip) + " " + std::string(to_string(e.pin)) + (e.value ? " 1" : " 0");
      if (e.pin == TracePin::SW_AXIS) s += " axis";
      break;
    case TraceEventKind::fault:
      s += " fault " + std::to_string(e.chip) + " " + std::string(to_string(e.fault));
      if (e.fault == TraceFault::POWER_CYCLE || e.fault == TraceFault::LOST_FRAME) break;  // no value
      s += ' ';
      if (e.fault == TraceFault::MISO_FLIP)
        s += std::to_string(e.value & 7u);
      else if (e.fault == TraceFault::THERMAL)
        s += thermal_name(e.value);
      else if (e.fault == TraceFault::ADCIN)
        s += std::to_string(e.value);
      else
        s += e.value ? "on" : "off";
      break;
    case TraceEventKind::load:
      s += " load " + std::to_string(e.chip) + " inertia=" + std::to_string(e.load.inertia_g_mm2) +
           " friction=" + std::to_string(e.load.friction_uNm) + " force=" + std::to_string(e.load.force_uNm);
      break;
    case TraceEventKind::advance:
      s += " advance";
      break;
    case TraceEventKind::axis:
      s += " axis " + std::to_string(e.chip) + " ";
      s += e.text.empty() ? std::string_view("default") : e.text;
      break;
    case TraceEventKind::stops:
      s += " stops " + std::to_string(e.chip) + " ";
      if (e.has_lower_stop) s += std::to_string(e.lower_stop);
      s += "..";
      if (e.has_upper_stop) s += std::to_string(e.upper_stop);
      break;
    case TraceEventKind::supply:
      s += " supply " + std::to_string(e.chip) + " " + std::to_string(e.supply_mV);
      break;
  }
}

std::string to_native_text(const Trace& trace, bool compact) {
  std::ostringstream out;
  NativeTraceWriter w(out, NativeWriteOptions{false, compact});
  w.write_header(trace.header);
  for (std::size_t i = 0; i < trace.size(); ++i) w.write(trace[i]);
  w.finish();
  return out.str();
}

Trace read_native_trace(std::string_view text, const std::string& name, std::uint64_t max_frames) {
  NativeTraceReader reader(text, name, max_frames);
  Trace t;
  t.header = reader.header();
  TraceEvent e;
  while (reader.next(e)) t.write(e);
  return t;
}

}  // namespace l6470emu
