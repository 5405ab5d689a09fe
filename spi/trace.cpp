// Trace: the in-memory trace, exact decimal time parsing and the names used by every format.
#include "spi/trace.hpp"

#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace l6470emu {

std::string_view to_string(TracePin pin) {
  switch (pin) {
    case TracePin::SW: return "SW";
    case TracePin::STCK: return "STCK";
    case TracePin::STBY: return "STBY";
    case TracePin::BUSY: return "BUSY";
    case TracePin::FLAG: return "FLAG";
    case TracePin::SW_AXIS: return "SW";
    case TracePin::DIR: return "DIR";
  }
  return "?";
}

std::string_view to_string(TraceFault fault) {
  switch (fault) {
    case TraceFault::UVLO: return "UVLO";
    case TraceFault::UVLO_ADC: return "UVLO_ADC";
    case TraceFault::OCD: return "OCD";
    case TraceFault::STALL_A: return "STALL_A";
    case TraceFault::STALL_B: return "STALL_B";
    case TraceFault::THERMAL: return "THERMAL";
    case TraceFault::ADCIN: return "ADCIN";
    case TraceFault::POWER_CYCLE: return "POWER_CYCLE";
    case TraceFault::MISO_FLIP: return "MISO_FLIP";
    case TraceFault::LOST_FRAME: return "LOST_FRAME";
  }
  return "?";
}

std::string_view thermal_name(std::uint8_t value) {
  static constexpr std::string_view kNames[] = {"normal", "warning", "bridge_shutdown", "device_shutdown"};
  return value < 4 ? kNames[value] : "?";
}

TraceError::TraceError(std::string file, std::uint64_t line, const std::string& message)
    : std::runtime_error((line ? file + ":" + std::to_string(line) : file) + ": " + message),
      file_(std::move(file)),
      line_(line),
      reason_(message) {}

// ---------------------------------------------------------------- Trace

void Trace::write(const TraceEvent& e) {
  Stored s{};
  s.tick = e.tick;
  s.duration = e.duration;
  s.source_time = e.source_time;
  s.line = e.line;
  s.repetition = e.repetition;
  s.chip = e.chip;
  s.kind = e.kind;
  s.value = e.value;
  s.what = e.kind == TraceEventKind::pin ? static_cast<std::uint8_t>(e.pin) : static_cast<std::uint8_t>(e.fault);
  // The numbers and text of the rare events go to the byte pool (Stored stays small).
  auto put = [this](std::uint64_t w, int n) {
    for (int b = 0; b < n; ++b) bytes_.push_back(static_cast<std::uint8_t>(w >> (8 * b)));
  };
  if (e.kind == TraceEventKind::load) {
    s.offset = bytes_.size();
    put(e.load.inertia_g_mm2, 4);
    put(e.load.friction_uNm, 4);
    put(static_cast<std::uint32_t>(e.load.force_uNm), 4);
  }
  if (e.kind == TraceEventKind::axis) {
    s.offset = bytes_.size();
    s.length = static_cast<std::uint32_t>(e.text.size());
    bytes_.insert(bytes_.end(), e.text.begin(), e.text.end());
  }
  if (e.kind == TraceEventKind::stops) {
    s.offset = bytes_.size();
    s.value = static_cast<std::uint8_t>((e.has_lower_stop ? 1 : 0) | (e.has_upper_stop ? 2 : 0));
    put(static_cast<std::uint64_t>(e.lower_stop), 8);
    put(static_cast<std::uint64_t>(e.upper_stop), 8);
  }
  if (e.kind == TraceEventKind::supply) {
    s.offset = bytes_.size();
    put(e.supply_mV, 4);
  }
  if (e.kind == TraceEventKind::frame) {
    if ((!e.miso.empty() && e.miso.size() != e.mosi.size()) ||
        (!e.miso_known.empty() && e.miso_known.size() != e.mosi.size()))
      throw std::invalid_argument("trace frame: MISO and MOSI lengths differ");
    ++frames_;
    s.offset = bytes_.size();
    s.length = static_cast<std::uint32_t>(e.mosi.size());
    bytes_.insert(bytes_.end(), e.mosi.begin(), e.mosi.end());
    if (!e.miso.empty()) {
      bytes_.insert(bytes_.end(), e.miso.begin(), e.miso.end());
      s.miso = 1;
      if (!e.miso_known.empty()) {
        bytes_.insert(bytes_.end(), e.miso_known.begin(), e.miso_known.end());
        s.miso = 2;
      }
    }
    if (e.wire.known) {
      if (wires_.empty() || !(wires_.back() == e.wire)) wires_.push_back(e.wire);
      s.wire = static_cast<std::uint32_t>(wires_.size());
    }
  }
  events_.push_back(s);
}

TraceEvent Trace::operator[](std::size_t i) const {
  const Stored& s = events_[i];
  TraceEvent e;
  e.kind = s.kind;
  e.tick = s.tick;
  e.duration = s.duration;
  e.source_time = s.source_time;
  e.line = s.line;
  e.repetition = s.repetition;
  e.chip = s.chip;
  e.value = s.value;
  if (s.kind == TraceEventKind::pin) e.pin = static_cast<TracePin>(s.what);
  if (s.kind == TraceEventKind::fault) e.fault = static_cast<TraceFault>(s.what);
  auto get = [this, &s](std::size_t at, int n) {
    std::uint64_t w = 0;
    for (int b = 0; b < n; ++b) w |= std::uint64_t{bytes_[s.offset + at + static_cast<std::size_t>(b)]} << (8 * b);
    return w;
  };
  if (s.kind == TraceEventKind::load) {
    e.load.inertia_g_mm2 = static_cast<std::uint32_t>(get(0, 4));
    e.load.friction_uNm = static_cast<std::uint32_t>(get(4, 4));
    e.load.force_uNm = static_cast<std::int32_t>(static_cast<std::uint32_t>(get(8, 4)));
  }
  if (s.kind == TraceEventKind::axis)
    e.text = {reinterpret_cast<const char*>(bytes_.data() + s.offset), s.length};
  if (s.kind == TraceEventKind::stops) {
    e.value = 0;
    e.has_lower_stop = (s.value & 1) != 0;
    e.has_upper_stop = (s.value & 2) != 0;
    e.lower_stop = static_cast<std::int64_t>(get(0, 8));
    e.upper_stop = static_cast<std::int64_t>(get(8, 8));
  }
  if (s.kind == TraceEventKind::supply) e.supply_mV = static_cast<std::uint32_t>(get(0, 4));
  if (s.kind == TraceEventKind::frame) {
    const std::uint8_t* p = bytes_.data() + s.offset;
    e.mosi = {p, s.length};
    if (s.miso >= 1) e.miso = {p + s.length, s.length};
    if (s.miso == 2) e.miso_known = {p + 2 * std::size_t{s.length}, s.length};
    if (s.wire != 0) e.wire = wires_[s.wire - 1];
  }
  return e;
}

namespace {

class TraceCursor final : public TraceReader {
 public:
  explicit TraceCursor(const Trace& t) : trace_(t) {}
  const TraceHeader& header() const override { return trace_.header; }
  bool next(TraceEvent& e) override {
    if (i_ >= trace_.size()) return false;
    e = trace_[i_++];
    return true;
  }
  ReadProgress progress() const override { return {i_, trace_.size(), false}; }

 private:
  const Trace& trace_;
  std::size_t i_ = 0;
};

}  // namespace

std::unique_ptr<TraceReader> Trace::reader() const { return std::make_unique<TraceCursor>(*this); }

// ---------------------------------------------------------------- time

bool parse_source_time(std::string_view text, int unit_exp10, SourceTime& out) {
  return parse_source_time_checked(text, unit_exp10, out) == TimeParse::ok;
}

TimeParse parse_source_time_checked(std::string_view text, int unit_exp10, SourceTime& out) {
  std::size_t i = 0;
  bool negative = false;
  if (i < text.size() && (text[i] == '-' || text[i] == '+')) negative = text[i++] == '-';
  // Mantissa digits and where the decimal point is.
  const std::size_t digits_begin = i;
  std::size_t point = std::string_view::npos;
  std::size_t digit_count = 0;
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c >= '0' && c <= '9') {
      ++digit_count;
    } else if (c == '.' && point == std::string_view::npos) {
      point = digit_count;
    } else {
      break;
    }
  }
  if (digit_count == 0) return TimeParse::malformed;
  const std::size_t digits_end = i;
  if (point == std::string_view::npos) point = digit_count;
  long exponent = 0;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    bool exp_negative = false;
    if (i < text.size() && (text[i] == '-' || text[i] == '+')) exp_negative = text[i++] == '-';
    std::size_t exp_digits = 0;
    for (; i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i, ++exp_digits) {
      exponent = exponent * 10 + (text[i] - '0');
      if (exponent > 100000) {
        // Too many exponent digits to be a time; still tell a number from garbage.
        while (i < text.size() && text[i] >= '0' && text[i] <= '9') ++i;
        return i == text.size() ? TimeParse::out_of_range : TimeParse::malformed;
      }
    }
    if (exp_digits == 0) return TimeParse::malformed;
    if (exp_negative) exponent = -exponent;
  }
  if (i != text.size()) return TimeParse::malformed;

  // Digit k (0-based over the mantissa) stands for 10^(point - 1 - k + exponent + unit) seconds.
  static constexpr std::int64_t kPow10[] = {1,          10,          100,          1000,          10000,
                                            100000,     1000000,     10000000,     100000000,     1000000000,
                                            10000000000, 100000000000, 1000000000000};
  std::int64_t seconds = 0, ps = 0;
  bool round_up = false, rounded = false;
  std::size_t k = 0;
  for (std::size_t j = digits_begin; j < digits_end; ++j) {
    if (text[j] == '.') continue;
    const int d = text[j] - '0';
    const long p = static_cast<long>(point) - 1 - static_cast<long>(k) + exponent + unit_exp10;
    ++k;
    if (p >= 0) {
      // seconds += d * 10^p; only sane captures (below 10^18 s) are accepted.
      if (p > 17) {
        if (d != 0) return TimeParse::out_of_range;
        continue;
      }
      std::int64_t add = d;
      for (long q = 0; q < p; ++q) add *= 10;
      if (seconds > 9'000'000'000'000'000'000 - add) return TimeParse::out_of_range;
      seconds += add;
    } else if (p >= -12) {
      ps += d * kPow10[12 + p];
    } else if (!rounded) {
      round_up = d >= 5;
      rounded = true;
    }
  }
  if (round_up && ++ps == kPow10[12]) {
    ps = 0;
    ++seconds;
  }
  if (negative && (seconds != 0 || ps != 0)) {
    seconds = -seconds;
    if (ps != 0) {
      --seconds;
      ps = kPow10[12] - ps;
    }
  }
  out = {seconds, ps};
  return TimeParse::ok;
}

bool ticks_between(const SourceTime& origin, const SourceTime& t, Tick& out) {
  if (t < origin) return false;
  // 104 days: no capture is that long (compared so that nothing overflows: both are within ±9e18 s).
  if (t.seconds - 9'000'000 > origin.seconds) return false;
  const std::int64_t ds = t.seconds - origin.seconds;
  const std::int64_t ps = ds * 1'000'000'000'000 + (t.picoseconds - origin.picoseconds);
  constexpr std::int64_t kPsPerTick = 250'000;
  out = static_cast<Tick>((ps + kPsPerTick / 2) / kPsPerTick);
  return true;
}

std::string too_many_frames(std::uint64_t max_frames) {
  return "more than " + std::to_string(max_frames) +
         " frames, the limit (raise it with --max-frames N, or max_frames=N in Python; 0 = no limit)";
}

std::string frame_too_long(std::uint64_t bytes) {
  return "a frame of " + std::to_string(bytes) + " bytes or more: a trace frame holds at most " +
         std::to_string(kMaxTraceFrameBytes) + " bytes";
}

std::string line_too_long() {
  return "a line longer than " + std::to_string(kMaxTraceLineBytes) + " bytes (a frame holds at most " +
         std::to_string(kMaxTraceFrameBytes) + " bytes: not a trace, or a damaged one)";
}

namespace {

// Every trace line starts with a time, and a recording writes one per frame: digits go two at a
// time, into a buffer on the stack, then into the string at once.
constexpr char kDigitPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

/// Writes `v` in decimal so that it ends just before `end`; returns where it starts.
char* put_decimal(char* end, std::uint64_t v) {
  while (v >= 100) {
    end -= 2;
    std::memcpy(end, kDigitPairs + 2 * (v % 100), 2);
    v /= 100;
  }
  if (v >= 10) {
    end -= 2;
    std::memcpy(end, kDigitPairs + 2 * v, 2);
  } else {
    *--end = static_cast<char>('0' + v);
  }
  return end;
}

/// Writes the 2 * `pairs` lowest decimal digits of `v` (zeros in front) just before `end`.
char* put_digit_pairs(char* end, std::uint64_t v, int pairs) {
  for (int i = 0; i < pairs; ++i) {
    end -= 2;
    std::memcpy(end, kDigitPairs + 2 * (v % 100), 2);
    v /= 100;
  }
  return end;
}

}  // namespace

namespace {

/// `t` in units of `per_unit` ticks with 2 * `pairs` decimals (each tick 25 hundred-millionths of
/// a second: exact), written at `out`; returns the end.
char* write_ticks_as(char* out, Tick t, Tick per_unit, int pairs) {
  char buf[kMaxTimeChars];
  char* const end = buf + sizeof buf;
  char* p = put_digit_pairs(end, (t % per_unit) * 25, pairs);
  *--p = '.';
  p = put_decimal(p, t / per_unit);
  const auto n = static_cast<std::size_t>(end - p);
  std::memcpy(out, p, n);
  return out + n;
}

}  // namespace

char* write_seconds(char* out, Tick t) {
  // A recording writes one per frame line: the usual times (under 10 000 s) without the general
  // path's 64-bit divisions, buffer and copy; its 8 decimals as two halves of 4 in 32 bits.
  const std::uint64_t whole = t / kTicksPerSecond;
  if (whole >= 10'000) return write_ticks_as(out, t, kTicksPerSecond, 4);
  const auto w = static_cast<std::uint32_t>(whole);
  const auto fraction = static_cast<std::uint32_t>(t - whole * kTicksPerSecond) * 25u;  // < 10^8
  if (w >= 1000) *out++ = static_cast<char>('0' + w / 1000);
  if (w >= 100) *out++ = static_cast<char>('0' + w / 100 % 10);
  if (w >= 10) *out++ = static_cast<char>('0' + w / 10 % 10);
  *out++ = static_cast<char>('0' + w % 10);
  *out++ = '.';
  const std::uint32_t high = fraction / 10'000, low = fraction % 10'000;
  std::memcpy(out, kDigitPairs + 2 * (high / 100), 2);
  std::memcpy(out + 2, kDigitPairs + 2 * (high % 100), 2);
  std::memcpy(out + 4, kDigitPairs + 2 * (low / 100), 2);
  std::memcpy(out + 6, kDigitPairs + 2 * (low % 100), 2);
  return out + 8;
}

char* write_microseconds(char* out, Tick t) { return write_ticks_as(out, t, kTicksPerMicrosecond, 1); }

void append_seconds(std::string& out, Tick t) {
  char buf[kMaxTimeChars];
  out.append(buf, static_cast<std::size_t>(write_seconds(buf, t) - buf));
}

void append_microseconds(std::string& out, Tick t) {
  char buf[kMaxTimeChars];
  out.append(buf, static_cast<std::size_t>(write_microseconds(buf, t) - buf));
}

char* write_hex_bytes(char* p, std::span<const std::uint8_t> bytes, std::span<const std::uint8_t> known) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    if (i) *p++ = ' ';
    if (!known.empty() && !known[i]) {
      *p++ = '?';
      *p++ = '?';
      continue;
    }
    *p++ = kHex[bytes[i] >> 4];
    *p++ = kHex[bytes[i] & 15];
  }
  return p;
}

void append_hex_bytes(std::string& out, std::span<const std::uint8_t> bytes, std::span<const std::uint8_t> known) {
  if (bytes.empty()) return;
  const std::size_t at = out.size();
  out.resize(at + 3 * bytes.size() - 1);
  write_hex_bytes(out.data() + at, bytes, known);
}

std::string format_seconds(Tick t) {
  std::string s;
  append_seconds(s, t);
  return s;
}

std::string format_microseconds(Tick t) {
  std::string s;
  append_microseconds(s, t);
  return s;
}

std::string hex_bytes(std::span<const std::uint8_t> bytes, std::span<const std::uint8_t> known) {
  std::string s;
  s.reserve(bytes.size() * 3);
  append_hex_bytes(s, bytes, known);
  return s;
}

}  // namespace l6470emu
