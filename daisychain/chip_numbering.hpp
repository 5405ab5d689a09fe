// How users number the chips of a chain: from the MISO end (the chain's own indices) or from
// the MOSI end (as ST's powerSTEP01 BSP and many host libraries do). Only what users read and
// write is translated; every index inside the emulator stays MISO-based.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace l6470emu {

/// Which end of a chain chip 0 is at.
enum class NumberFrom : std::uint8_t {
  miso,  ///< chip 0 drives MISO (the chain's own indices; byte k of a full frame is chip k's)
  mosi,  ///< chip 0 reads the host's MOSI (the chain's chip N-1; it gets a full frame's last byte)
};

/// "miso" or "mosi".
const char* to_string(NumberFrom from);

/// The convention called `name` ("miso" or "mosi", case-insensitive), or nothing.
std::optional<NumberFrom> number_from_named(std::string_view name);

/// The convention called `name`. Throws std::invalid_argument with one line naming the text
/// and the two choices ("'x' is not a chip numbering: write miso (...) or mosi (...)").
NumberFrom parse_number_from(std::string_view name);

/// One line saying what chip numbers mean under `from`, for the head of a report:
/// "chip numbers count from the MISO end (chip 0 drives MISO)".
std::string describe_numbering(NumberFrom from);

/// The error for a trace event that names chip `chip` of a chain of `chips` chips. Trace
/// files always number chips from the MISO end, whatever the reader shows, and this says so.
std::string trace_chip_outside_chain(std::size_t chip, std::size_t chips);

/// The chip numbers of one chain as a user sees them: a chain index (chip(i), MISO-based)
/// turned into the number shown, and a number typed by the user turned into an index.
class ChipNumbering {
 public:
  /// MISO numbering of an empty chain (every index is its own number).
  ChipNumbering() = default;
  /// `from`'s numbering of a chain of `chips` chips.
  ChipNumbering(NumberFrom from, std::size_t chips) : from_(from), chips_(chips) {}

  NumberFrom from() const { return from_; }
  std::size_t chips() const { return chips_; }

  /// The number users see for chain index `index` (< chips()).
  std::size_t number_of(std::size_t index) const { return from_ == NumberFrom::miso ? index : chips_ - 1 - index; }
  /// The chain index of user number `number` (< chips()). The mapping is its own inverse.
  std::size_t index_of(std::size_t number) const { return number_of(number); }
  /// "chip N" for chain index `index`.
  std::string label(std::size_t index) const { return "chip " + std::to_string(number_of(index)); }
  /// describe_numbering(from()).
  std::string description() const { return describe_numbering(from_); }

 private:
  NumberFrom from_ = NumberFrom::miso;
  std::size_t chips_ = 0;
};

}  // namespace l6470emu
