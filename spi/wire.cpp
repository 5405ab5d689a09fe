// WireSettings in words, for diagnostics and reports.
#include "spi/wire.hpp"

namespace l6470emu {

std::string describe_speed(std::uint32_t hz) {
  if (hz != 0 && hz % 1'000'000 == 0) return std::to_string(hz / 1'000'000) + " MHz";
  if (hz != 0 && hz % 1000 == 0) return std::to_string(hz / 1000) + " kHz";
  return std::to_string(hz) + " Hz";
}

std::string describe_wire(const WireSettings& wire) {
  const unsigned mode = wire.mode & 3u;
  std::string s = "mode " + std::to_string(mode) + " (CPOL=" + std::to_string(mode >> 1) +
                  ", CPHA=" + std::to_string(mode & 1u) + ")";
  if (wire.lsb_first) s += ", LSB first";
  if (wire.cs_active_high) s += ", CS active high";
  if (wire.bits_per_word != 8) s += ", " + std::to_string(wire.bits_per_word) + "-bit words";
  if (wire.speed_hz != 0) s += ", " + describe_speed(wire.speed_hz);
  return s;
}

}  // namespace l6470emu
