// How a host drove the wire during a trace's frames (the native format's `wire` lines, version 3):
// the settings that decide which bits the chips see and the host reads. The settings only; the
// edge rules are spi/wire.hpp's and the chain applies them (daisychain/).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "spi/wire.hpp"

namespace l6470emu {

/// The host's wire settings in force during a frame, as a trace carries them. A trace that says
/// nothing (a capture, a native file of version 1 or 2, a frame clocked through the byte face)
/// has `known` false and the other fields at their defaults: SPI mode 3, MSB first, CS edges
/// without t_disCS, which is how such frames have always been replayed.
struct TraceWire {
  /// The trace said how the host drove the wire (a `wire` line was in force).
  bool known = false;
  std::uint8_t mode = 3;           ///< SPI mode: CPOL << 1 | CPHA (0..3)
  bool lsb_first = false;          ///< each byte shifted least significant bit first
  std::uint8_t bits_per_word = 8;  ///< the host's word size (the bytes are in wire order already)
  std::uint32_t speed_hz = 0;      ///< SCK of the frame's first transfer, Hz (0 = not known)
  /// The front's CS edges take bus time, so a CS high shorter than t_disCS (kDeselectMinTicks)
  /// before this frame left the chips no time to load their answers (Chain::select_wire). False
  /// for a front whose time moves only when told (Python's Chain.frame) and for unknown wires.
  bool deselect_timed = false;

  /// The settings as the chain's bit-level face takes them.
  WireSettings settings() const;
  /// Whether two frames were clocked alike (`known` aside: an unknown wire is its defaults).
  bool same_as(const TraceWire& o) const {
    return mode == o.mode && lsb_first == o.lsb_first && bits_per_word == o.bits_per_word && speed_hz == o.speed_hz &&
           deselect_timed == o.deselect_timed;
  }
  friend bool operator==(const TraceWire&, const TraceWire&) = default;
};

/// The fastest SCK a `wire` line may name (1 GHz: far beyond any controller; a bound for readers).
inline constexpr std::uint32_t kMaxTraceWireSpeedHz = 1'000'000'000;

/// The wire of a host with `wire` settings whose CS edges are timed or not (a recording).
inline TraceWire trace_wire_of(const WireSettings& wire, bool deselect_timed) {
  TraceWire t;
  t.known = true;
  t.mode = static_cast<std::uint8_t>(wire.mode & 3u);
  t.lsb_first = wire.lsb_first;
  t.bits_per_word = wire.bits_per_word == 0 ? std::uint8_t{8} : wire.bits_per_word;
  t.speed_hz = wire.speed_hz > kMaxTraceWireSpeedHz ? kMaxTraceWireSpeedHz : wire.speed_hz;
  t.deselect_timed = deselect_timed;
  return t;
}

/// The native line's body after its time: " wire mode=0 order=msb bits=8 speed=5000000 deselect=timed".
void append_wire_body(std::string& out, const TraceWire& wire);

/// Parses the fields of a `wire` line after the word `wire` into `out` (known); returns "" or
/// what is wrong, in words that name the field.
std::string parse_wire_fields(std::string_view fields, TraceWire& out);

/// The form of a `wire` line, for messages.
inline constexpr std::string_view kWireLineForm =
    "'TIME wire mode=0..3 order=msb|lsb bits=1..32 speed=HZ deselect=timed|untimed'";

/// "mode 0 (CPOL=0, CPHA=0), 16-bit words, 5 MHz" for logs, with ", speed not known" and ", CS
/// edges untimed (no t_disCS)" where they apply.
std::string describe_trace_wire(const TraceWire& wire);

}  // namespace l6470emu
