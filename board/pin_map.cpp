// Microcontroller pin names (Arduino numbers, STM32 port pins) and SPI controller names, as the
// board description writes them.
#include "board/pin_map.hpp"

#include <cctype>
#include <charconv>

namespace l6470emu {
namespace {

std::string upper(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

// A plain decimal number without sign or leading '+' (leading zeros allowed), at most `max`.
std::optional<unsigned> number(std::string_view s, unsigned max) {
  if (s.empty() || s.size() > 4) return std::nullopt;
  unsigned v = 0;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v, 10);
  if (ec != std::errc{} || p != s.data() + s.size() || v > max) return std::nullopt;
  return v;
}

}  // namespace

std::optional<McuPin> parse_mcu_pin(std::string_view text) {
  const std::string t = upper(text);
  const std::string_view s = t;
  auto arduino = [](unsigned n) { return McuPin{McuPin::Kind::arduino, static_cast<std::uint16_t>(n)}; };
  if (!s.empty() && std::isdigit(static_cast<unsigned char>(s[0]))) {
    if (const auto n = number(s, kMaxArduinoPin)) return arduino(*n);
    return std::nullopt;
  }
  if (s.size() >= 2 && s[0] == 'D' && std::isdigit(static_cast<unsigned char>(s[1]))) {
    if (const auto n = number(s.substr(1), kMaxArduinoPin)) return arduino(*n);
    return std::nullopt;
  }
  if (s.size() == 2 && s[0] == 'A' && s[1] >= '0' && s[1] <= '7') return arduino(kArduinoA0 + unsigned(s[1] - '0'));
  if (s.substr(0, 4) == "GPIO") {
    if (const auto n = number(s.substr(4), kMaxArduinoPin)) return arduino(*n);
    return std::nullopt;
  }
  if (s.size() >= 3 && s[0] == 'P' && s[1] >= 'A' && s[1] < char('A' + kStm32Ports)) {
    if (const auto n = number(s.substr(2), 15))
      return McuPin{McuPin::Kind::stm32, static_cast<std::uint16_t>(unsigned(s[1] - 'A') * 16 + *n)};
  }
  return std::nullopt;
}

std::string to_string(const McuPin& pin) {
  if (pin.kind == McuPin::Kind::arduino) return std::to_string(pin.number);
  return std::string("P") + char('A' + pin.number / 16) + std::to_string(pin.number % 16);
}

const char* pin_key(Pin p) {
  static const char* const keys[] = {"busy_pin", "flag_pin", "sw_pin", "stck_pin", "stby_rst_pin", "dir_pin"};
  return keys[static_cast<unsigned>(p)];
}

std::optional<std::string> parse_spi_controller(std::string_view text) {
  const std::string t = upper(text);
  if (t == "SPI" || t == "HSPI" || t == "VSPI" || t == "FSPI") return t;
  for (const std::string_view prefix : {"SPI", "HSPI"}) {
    if (t.size() == prefix.size() + 1 && t.substr(0, prefix.size()) == prefix && t.back() >= '1' && t.back() <= '9')
      return "SPI" + t.substr(prefix.size());
  }
  return std::nullopt;
}

std::optional<McuPin> chip_mcu_pin(const ChainPins& pins, Pin pin, std::size_t user_chip) {
  const ChipPinList& list = pins.chip[static_cast<unsigned>(pin)];
  if (list.empty()) return std::nullopt;
  if (list.size() == 1) return list[0];
  return user_chip < list.size() ? list[user_chip] : std::nullopt;
}

}  // namespace l6470emu
