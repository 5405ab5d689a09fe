// Suggestions for misspelt names ("did you mean MAX_SPEED?"): edit distance over short words.
// Used wherever a name from outside is looked up: variants, registers, keys, options.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace l6470emu {

/// Edit distance between `a` and `b` (insertions, deletions, substitutions and swaps of two
/// neighbouring letters, one each), ignoring ASCII case.
std::size_t edit_distance(std::string_view a, std::string_view b);

/// The candidates closest to `word` (at most 2 edits, and fewer edits than the word has
/// characters), in the order given; none when nothing is close.
std::vector<std::string> closest_matches(std::string_view word, const std::vector<std::string>& candidates);

/// The candidates closest to `word` (at most 2 edits, and fewer edits than the word has
/// characters), as "A", "A or B" or "A, B or C"; "" when nothing is close.
std::string closest_names(std::string_view word, const std::vector<std::string>& candidates);

/// "did you mean L6470 or L6472? " for a misspelt variant name, else "".
std::string variant_suggestion(std::string_view name);

/// The variant names, comma separated: "L6470, L6472, L6480, L6482, powerSTEP01, L6474".
std::string known_variant_list();

}  // namespace l6470emu
