// TraceWire: the host's wire settings of a trace's frames, as the native format writes and reads
// them (`TIME wire mode=M order=msb|lsb bits=B speed=HZ deselect=timed|untimed`).
#include "spi/trace_wire.hpp"

#include "spi/import_support.hpp"

namespace l6470emu {
namespace {

using detail::next_token;

bool parse_number(std::string_view s, std::uint64_t max, std::uint64_t& out) {
  if (s.empty() || s.size() > 12) return false;
  std::uint64_t v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + static_cast<std::uint64_t>(c - '0');
  }
  if (v > max) return false;
  out = v;
  return true;
}

}  // namespace

WireSettings TraceWire::settings() const {
  WireSettings w;
  w.mode = static_cast<std::uint8_t>(mode & 3u);
  w.lsb_first = lsb_first;
  w.bits_per_word = bits_per_word;
  w.speed_hz = speed_hz;
  return w;
}

void append_wire_body(std::string& out, const TraceWire& wire) {
  out += " wire mode=";
  out += static_cast<char>('0' + (wire.mode & 3u));
  out += wire.lsb_first ? " order=lsb" : " order=msb";
  out += " bits=" + std::to_string(unsigned{wire.bits_per_word});
  out += " speed=" + std::to_string(wire.speed_hz);
  out += wire.deselect_timed ? " deselect=timed" : " deselect=untimed";
}

std::string parse_wire_fields(std::string_view fields, TraceWire& out) {
  static constexpr std::string_view kNames[] = {"mode=", "order=", "bits=", "speed=", "deselect="};
  TraceWire w;
  w.known = true;
  for (const std::string_view name : kNames) {
    const std::string_view tok = next_token(fields);
    if (tok.substr(0, name.size()) != name) {
      if (tok.empty()) return "wire: " + std::string(name) + "... is missing";
      return "wire: " + detail::quote(tok) + " where " + std::string(name) + "... belongs";
    }
    const std::string_view value = tok.substr(name.size());
    std::uint64_t n = 0;
    if (name == "mode=") {
      if (!parse_number(value, 3, n)) return "wire: mode " + detail::quote(value) + " is not an SPI mode (0..3)";
      w.mode = static_cast<std::uint8_t>(n);
    } else if (name == "order=") {
      if (value != "msb" && value != "lsb") return "wire: order " + detail::quote(value) + " is not msb or lsb";
      w.lsb_first = value == "lsb";
    } else if (name == "bits=") {
      if (!parse_number(value, 32, n) || n == 0)
        return "wire: bits " + detail::quote(value) + " is not a word size (1..32 bits)";
      w.bits_per_word = static_cast<std::uint8_t>(n);
    } else if (name == "speed=") {
      if (!parse_number(value, kMaxTraceWireSpeedHz, n))
        return "wire: speed " + detail::quote(value) + " is not a clock in Hz (0..1000000000; 0 = not known)";
      w.speed_hz = static_cast<std::uint32_t>(n);
    } else {
      if (value != "timed" && value != "untimed") return "wire: deselect " + detail::quote(value) + " is not timed or untimed";
      w.deselect_timed = value == "timed";
    }
  }
  if (!next_token(fields).empty()) return "too many fields in the wire line";
  out = w;
  return {};
}

std::string describe_trace_wire(const TraceWire& wire) {
  std::string s = describe_wire(wire.settings());
  if (wire.speed_hz == 0) s += ", speed not known";
  if (!wire.deselect_timed) s += ", CS edges untimed (no t_disCS)";
  return s;
}

}  // namespace l6470emu
