// A count with its noun in the right number for messages: "1 chip", "3 chips", "1 diagnosis".
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace l6470emu {

/// "1 chip", "0 chips", "3 chips"; `plural` when the noun does not take an s ("1 match", "2 matches").
inline std::string counted(std::uint64_t n, std::string_view singular, std::string_view plural = {}) {
  std::string out = std::to_string(n) + " ";
  if (n == 1) return out.append(singular);
  if (!plural.empty()) return out.append(plural);
  return out.append(singular).append("s");
}

}  // namespace l6470emu
