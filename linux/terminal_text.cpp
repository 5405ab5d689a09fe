// Text from a source that is not trusted, made safe to print on a terminal.
#include "linux/terminal_text.hpp"

#include <cstdint>
#include <cstdio>

namespace l6470emu {
namespace {

void hex_byte(std::string& out, unsigned char c) {
  char b[8];
  std::snprintf(b, sizeof b, "\\x%02X", c);
  out += b;
}

/// Length of the valid UTF-8 sequence at the start of `s` (0 when it is not one), and its code point.
std::size_t utf8_sequence(std::string_view s, std::uint32_t& code) {
  const auto b = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
  const unsigned char c = b(0);
  std::size_t n = 0;
  std::uint32_t min = 0;
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2;
    code = c & 0x1F;
    min = 0x80;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    code = c & 0x0F;
    min = 0x800;
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    code = c & 0x07;
    min = 0x10000;
  } else {
    return 0;
  }
  if (s.size() < n) return 0;
  for (std::size_t i = 1; i < n; ++i) {
    if ((b(i) & 0xC0) != 0x80) return 0;
    code = code << 6 | (b(i) & 0x3F);
  }
  if (code < min || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;  // overlong, beyond, surrogate
  return n;
}

}  // namespace

std::string terminal_safe(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\n' || c == '\t' || (c >= 0x20 && c < 0x7F)) {
      out += static_cast<char>(c);
      ++i;
      continue;
    }
    std::uint32_t code = 0;
    const std::size_t n = c >= 0x80 ? utf8_sequence(text.substr(i), code) : 0;
    // C1 controls (U+0080..U+009F) are escape sequences' introducers for many terminals.
    if (n > 0 && !(code >= 0x80 && code <= 0x9F)) {
      out.append(text.substr(i, n));
      i += n;
      continue;
    }
    if (n > 0) {
      for (std::size_t k = 0; k < n; ++k) hex_byte(out, static_cast<unsigned char>(text[i + k]));
      i += n;
      continue;
    }
    hex_byte(out, c);
    ++i;
  }
  return out;
}

}  // namespace l6470emu
