// Chip numbering conventions: names, parsing and the line that says which one is in use.
#include "daisychain/chip_numbering.hpp"
#include "core/counted.hpp"

#include <cctype>
#include <stdexcept>

namespace l6470emu {

const char* to_string(NumberFrom from) { return from == NumberFrom::mosi ? "mosi" : "miso"; }

std::optional<NumberFrom> number_from_named(std::string_view name) {
  std::string lower;
  for (char c : name) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (lower == "miso") return NumberFrom::miso;
  if (lower == "mosi") return NumberFrom::mosi;
  return std::nullopt;
}

NumberFrom parse_number_from(std::string_view name) {
  if (const auto from = number_from_named(name)) return *from;
  std::string shown;
  for (char c : name.substr(0, 40)) {
    const auto u = static_cast<unsigned char>(c);
    shown += u < 0x20 || u >= 0x7f ? '?' : c;
  }
  if (name.size() > 40) shown += "...";
  throw std::invalid_argument("'" + shown +
                              "' is not a chip numbering: write miso (chip 0 drives MISO) or mosi (chip 0 reads the "
                              "host's MOSI)");
}

std::string describe_numbering(NumberFrom from) {
  return from == NumberFrom::mosi
             ? "chip numbers count from the MOSI end (chip 0 reads the host's MOSI and gets a full frame's last byte)"
             : "chip numbers count from the MISO end (chip 0 drives MISO and gets a full frame's first byte)";
}

std::string trace_chip_outside_chain(std::size_t chip, std::size_t chips) {
  return "event for chip " + std::to_string(chip) + " (trace files count from the MISO end), but the chain has " +
         counted(chips, "chip") + " (see --chain)";
}

}  // namespace l6470emu
