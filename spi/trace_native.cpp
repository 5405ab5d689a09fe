// Native trace format, version 1: parsing line by line with exact times, and writing
// with one flush per event. The grammar is in docs/trace-format.md.
#include "spi/trace_native.hpp"

#include "spi/import_support.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace l6470emu {
namespace {

constexpr std::size_t kChunk = 1 << 20;

bool is_space(char c) { return c == ' ' || c == '\t'; }

/// Splits off the next whitespace-separated token of `rest`.
std::string_view next_token(std::string_view& rest) {
  std::size_t i = 0;
  while (i < rest.size() && is_space(rest[i])) ++i;
  std::size_t j = i;
  while (j < rest.size() && !is_space(rest[j])) ++j;
  const std::string_view tok = rest.substr(i, j - i);
  rest.remove_prefix(j);
  return tok;
}

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

bool parse_uint(std::string_view s, unsigned long max, unsigned long& out) {
  if (s.empty() || s.size() > 10) return false;
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

NativeTraceReader::NativeTraceReader(const std::string& path) {
  header_.name = path;
  header_.format = "native";
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) throw TraceError(path, 0, std::string("cannot open: ") + std::strerror(errno));
  // A small file gets a small buffer (it grows for a line longer than the buffer).
  struct stat st {};
  const bool sized = fstat(fileno(file_), &st) == 0 && S_ISREG(st.st_mode) && st.st_size >= 0;
  buffer_.resize(sized ? std::clamp<std::size_t>(static_cast<std::size_t>(st.st_size) + 1, 4096, kChunk) : kChunk);
  try {
    read_header();
  } catch (...) {
    // No destructor runs for a constructor that throws: close the file here.
    std::fclose(file_);
    file_ = nullptr;
    throw;
  }
}

NativeTraceReader::NativeTraceReader(std::string_view text, std::string name) : text_(text) {
  header_.name = std::move(name);
  header_.format = "native";
  eof_ = true;
  read_header();
}

NativeTraceReader::~NativeTraceReader() {
  if (file_ != nullptr) std::fclose(file_);
}

void NativeTraceReader::fail(const std::string& message) const {
  std::string m = message;
  if (last_line_unterminated_) m += " (the last line has no newline: truncated file?)";
  throw TraceError(header_.name, line_no_, m);
}

bool NativeTraceReader::next_line(std::string_view& line) {
  for (;;) {
    const std::size_t nl = text_.find('\n');
    if (nl != std::string_view::npos) {
      line = text_.substr(0, nl);
      text_.remove_prefix(nl + 1);
      ++line_no_;
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      return true;
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
    if (keep == buffer_.size()) buffer_.resize(buffer_.size() * 2);
    const std::size_t got = std::fread(buffer_.data() + keep, 1, buffer_.size() - keep, file_);
    if (got == 0) {
      if (std::ferror(file_)) throw TraceError(header_.name, line_no_ + 1, "read error");
      eof_ = true;
    }
    text_ = std::string_view(buffer_.data(), keep + got);
  }
}

void NativeTraceReader::read_header() {
  std::string_view line;
  if (!next_line(line)) throw TraceError(header_.name, 0, "empty file (expected a native trace: 'l6470emu-trace 1')");
  std::string_view rest = line;
  const std::string_view magic = next_token(rest);
  const std::string_view version = next_token(rest);
  if (magic != kNativeTraceMagic)
    fail("not an l6470emu trace: the first line must be 'l6470emu-trace " + std::to_string(kNativeTraceVersion) + "'");
  unsigned long v = 0;
  if (!parse_uint(version, 1000000, v) || !next_token(rest).empty()) fail("malformed header line " + quoted(line));
  if (v != static_cast<unsigned long>(kNativeTraceVersion))
    fail("format version " + std::to_string(v) + " (this l6470emu reads version " +
         std::to_string(kNativeTraceVersion) + ")");
  // Directives up to the first event.
  while (next_line(line)) {
    rest = line;
    const std::string_view word = next_token(rest);
    if (word.empty() || word[0] == '#') continue;
    if (word == "chain") {
      std::size_t i = 0;
      while (i < rest.size() && is_space(rest[i])) ++i;
      header_.chain = std::string(rest.substr(i));
      header_.chain_line = line_no_;
      if (header_.chain.empty()) fail("'chain' needs the chips, e.g. 'chain 3*L6470'");
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
  while (next_line(line)) {
    if (parse_line(line, e)) return true;
  }
  return false;
}

/// Parses one line into `e`; false for comments and blank lines.
bool NativeTraceReader::parse_line(std::string_view line, TraceEvent& e) {
  std::string_view rest = line;
  const std::string_view time_tok = next_token(rest);
  if (time_tok.empty() || time_tok[0] == '#') return false;
  if (time_tok[0] < '0' || time_tok[0] > '9') {
    if (time_tok == "chain") fail("'chain' must come before the first event");
    if (looks_like_a_time(time_tok)) fail(bad_time(time_tok));
    fail("unknown line " + quoted(line) + " (expected '<time> frame|pin|fault ...')");
  }

  // Time: seconds, decimal (the writer uses 8 decimals: exact ticks).
  Tick tick = 0;
  {
    std::uint64_t whole = 0;
    std::size_t i = 0;
    for (; i < time_tok.size() && time_tok[i] >= '0' && time_tok[i] <= '9'; ++i) {
      whole = whole * 10 + static_cast<std::uint64_t>(time_tok[i] - '0');
      if (whole > 1'000'000'000'000ull) fail("timestamp " + quoted(time_tok) + " is too large (at most 10^12 s)");
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
  }
  if (any_event_ && tick < last_tick_)
    fail("time " + as_written(time_tok, tick) + " s goes backwards (the previous event was at " + format_seconds(last_tick_) +
         " s)");

  e = TraceEvent{};
  e.tick = tick;
  e.line = line_no_;
  const std::string_view kind = next_token(rest);
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
        if (!ticks_between({}, d, ticks)) fail("frame duration " + quoted(tok) + " is too long");
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
    if (in_miso && miso_.size() != mosi_.size())
      fail("frame has " + std::to_string(mosi_.size()) + " MOSI bytes but " + std::to_string(miso_.size()) +
           " MISO bytes");
    e.mosi = mosi_;
    if (in_miso) e.miso = miso_;
    if (any_unknown) e.miso_known = known_;
    last_frame_end_ = e.end();
  } else if (kind == "pin" || kind == "fault") {
    const std::string_view chip_tok = next_token(rest);
    const std::string_view name = next_token(rest);
    const std::string_view value = next_token(rest);
    unsigned long chip = 0;
    if (!parse_uint(chip_tok, 255, chip)) fail("chip " + quoted(chip_tok) + " is not a chip number (0..255)");
    e.chip = static_cast<std::uint16_t>(chip);
    if (!next_token(rest).empty()) fail("too many fields in " + quoted(line));
    if (kind == "pin") {
      e.kind = TraceEventKind::pin;
      bool found = false;
      for (TracePin p : {TracePin::SW, TracePin::STCK, TracePin::STBY, TracePin::BUSY, TracePin::FLAG})
        if (name == to_string(p)) {
          e.pin = p;
          found = true;
        }
      if (!found) fail("unknown pin " + quoted(name) + " (SW, STCK, STBY, BUSY or FLAG)");
      if (value != "0" && value != "1") fail("pin level " + quoted(value) + " is not 0 or 1");
      e.value = value == "1";
    } else {
      e.kind = TraceEventKind::fault;
      bool found = false;
      for (TraceFault f : {TraceFault::UVLO, TraceFault::UVLO_ADC, TraceFault::OCD, TraceFault::STALL_A,
                           TraceFault::STALL_B, TraceFault::THERMAL, TraceFault::ADCIN})
        if (name == to_string(f)) {
          e.fault = f;
          found = true;
        }
      if (!found) fail("unknown fault " + quoted(name) + " (UVLO, UVLO_ADC, OCD, STALL_A, STALL_B, THERMAL or ADCIN)");
      if (e.fault == TraceFault::THERMAL) {
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
  } else if (kind.empty()) {
    fail("time without an event");
  } else {
    fail("unknown event " + quoted(kind) + " (frame, pin or fault)");
  }
  any_event_ = true;
  last_tick_ = tick;
  return true;
}

// ---------------------------------------------------------------- writer

NativeTraceWriter::NativeTraceWriter(const std::string& path, bool flush_each_event)
    : path_(path), flush_(flush_each_event) {
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) throw std::runtime_error(path + ": cannot create: " + std::strerror(errno));
  // Big enough that a line of a long frame leaves in one write.
  std::setvbuf(file_, nullptr, _IOFBF, 1 << 16);
}

NativeTraceWriter::NativeTraceWriter(std::ostream& out, bool flush_each_event) : out_(&out), flush_(flush_each_event) {}

NativeTraceWriter::~NativeTraceWriter() {
  if (file_ != nullptr) std::fclose(file_);
  else if (out_ != nullptr) out_->flush();
}

void NativeTraceWriter::put(const std::string& text) {
  if (file_ != nullptr) {
    if (std::fwrite(text.data(), 1, text.size(), file_) != text.size() || (flush_ && std::fflush(file_) != 0))
      throw std::runtime_error(path_ + ": write failed: " + std::strerror(errno));
  } else {
    out_->write(text.data(), static_cast<std::streamsize>(text.size()));
    if (flush_) out_->flush();
    if (!*out_) throw std::runtime_error("trace write failed");
  }
}

void NativeTraceWriter::write_header(const TraceHeader& header) {
  if (header_written_) return;
  header_written_ = true;
  std::string text = std::string(kNativeTraceMagic) + " " + std::to_string(kNativeTraceVersion) + "\n";
  if (!header.chain.empty()) text += "chain " + header.chain + "\n";
  if (!header.name.empty() && header.format != "native")
    text += "# converted from " + header.name + (header.format.empty() ? "" : " (" + header.format + ")") + "\n";
  for (const std::string& note : header.notes) text += "# note: " + note + "\n";
  put(text);
}

std::string NativeTraceWriter::format_event(const TraceEvent& e) {
  std::string s = format_seconds(e.tick);
  switch (e.kind) {
    case TraceEventKind::frame:
      s += " frame ";
      s += format_microseconds(e.duration);
      s += "us";
      if (!e.mosi.empty()) {
        s += ' ';
        s += hex_bytes(e.mosi);
      }
      if (!e.miso.empty()) {
        s += " |";
        if (!e.mosi.empty()) {
          s += ' ';
          s += hex_bytes(e.miso, e.miso_known);
        }
      }
      break;
    case TraceEventKind::pin:
      s += " pin " + std::to_string(e.chip) + " " + std::string(to_string(e.pin)) + (e.value ? " 1" : " 0");
      break;
    case TraceEventKind::fault:
      s += " fault " + std::to_string(e.chip) + " " + std::string(to_string(e.fault)) + " ";
      if (e.fault == TraceFault::THERMAL)
        s += thermal_name(e.value);
      else if (e.fault == TraceFault::ADCIN)
        s += std::to_string(e.value);
      else
        s += e.value ? "on" : "off";
      break;
  }
  return s;
}

void NativeTraceWriter::write(const TraceEvent& e) {
  if (!header_written_) write_header({});
  line_ = format_event(e);
  line_ += '\n';
  put(line_);
}

std::string to_native_text(const Trace& trace) {
  std::ostringstream out;
  {
    NativeTraceWriter w(out, false);
    w.write_header(trace.header);
    for (std::size_t i = 0; i < trace.size(); ++i) w.write(trace[i]);
  }
  return out.str();
}

Trace read_native_trace(std::string_view text, const std::string& name) {
  NativeTraceReader reader(text, name);
  Trace t;
  t.header = reader.header();
  TraceEvent e;
  while (reader.next(e)) t.write(e);
  return t;
}

}  // namespace l6470emu
