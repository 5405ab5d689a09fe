// "Did you mean ...?": the names closest to a mistyped word, for one-line error messages
// (board description keys and values, rule names, the preload's environment variables).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace l6470emu {

/// Levenshtein distance between `a` and `b`, ignoring ASCII case.
std::size_t edit_distance(std::string_view a, std::string_view b);

/// The candidates closest to `word` (at most 2 edits, and fewer than the word's length), as
/// "A", "A or B" or "A, B or C"; "" when nothing is close or the word is longer than 32 bytes.
std::string closest(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace l6470emu
