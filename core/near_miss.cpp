// Edit-distance suggestions for misspelt names.
#include "core/near_miss.hpp"

#include <algorithm>
#include <cctype>

#include "core/variant.hpp"

namespace l6470emu {
namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

// Only for the short words suggestions are made for (closest_names skips long ones).
std::size_t edit_distance(std::string_view a_in, std::string_view b_in) {
  const std::string a = lower(a_in), b = lower(b_in);
  // Two letters swapped ("chian") count as one edit (optimal string alignment distance).
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

std::vector<std::string> closest_matches(std::string_view word, const std::vector<std::string>& candidates) {
  if (word.empty() || word.size() > 32) return {};
  std::size_t best = 3;
  std::vector<std::string> hits;
  for (const auto& c : candidates) {
    if (c.size() > 64) continue;
    const std::size_t d = edit_distance(word, c);
    if (d >= word.size() || d > best) continue;
    if (d < best) hits.clear();
    best = d;
    if (std::find(hits.begin(), hits.end(), c) == hits.end()) hits.push_back(c);
  }
  return hits;
}

std::string closest_names(std::string_view word, const std::vector<std::string>& candidates) {
  const std::vector<std::string> hits = closest_matches(word, candidates);
  std::string out;
  for (std::size_t i = 0; i < hits.size(); ++i) out += (i == 0 ? "" : i + 1 == hits.size() ? " or " : ", ") + hits[i];
  return out;
}

std::string variant_suggestion(std::string_view name) {
  std::vector<std::string> names;
  for (const Variant* v : all_variants()) names.emplace_back(v->name);
  const std::string near = closest_names(name, names);
  return near.empty() ? "" : "did you mean " + near + "? ";
}

std::string known_variant_list() {
  std::string out;
  for (const Variant* v : all_variants()) out += (out.empty() ? "" : ", ") + std::string(v->name);
  return out;
}

}  // namespace l6470emu
