// Chain descriptions: parsing and printing "N*VARIANT" lists.
#include "daisychain/chain_spec.hpp"

#include <stdexcept>

#include "core/near_miss.hpp"
#include "spi/import_support.hpp"  // quote(): input in messages, cut short, control characters as \xNN

namespace l6470emu {

std::vector<const Variant*> parse_chain_spec(std::string_view spec) {
  std::vector<const Variant*> out;
  std::size_t i = 0;
  while (i < spec.size()) {
    while (i < spec.size() && (spec[i] == ',' || spec[i] == ' ' || spec[i] == '\t')) ++i;
    if (i == spec.size()) break;
    std::size_t j = i;
    while (j < spec.size() && spec[j] != ',' && spec[j] != ' ' && spec[j] != '\t') ++j;
    const std::string_view item = spec.substr(i, j - i);
    i = j;
    std::size_t count = 1;
    std::string_view name = item;
    std::size_t k = 0;
    while (k < item.size() && item[k] >= '0' && item[k] <= '9') ++k;
    if (k > 0) {
      if (k > 4) throw std::invalid_argument("chain item " + detail::quote(item) + ": too many chips");
      count = std::stoul(std::string(item.substr(0, k)));
      if (k == item.size()) {
        name = "L6470";
      } else if (item[k] == '*' || item[k] == 'x') {
        name = item.substr(k + 1);
        if (name.empty())
          throw std::invalid_argument("chain item " + detail::quote(item) + " has no variant after '" + item[k] +
                                      "' (N*VARIANT, e.g. 3*L6470)");
      } else {
        throw std::invalid_argument("chain item " + detail::quote(item) + " is not N, VARIANT or N*VARIANT");
      }
    }
    const Variant* v = find_variant(name);
    if (v == nullptr)
      throw std::invalid_argument("unknown chip variant " + detail::quote(name) + " (" + variant_suggestion(name) +
                                  "known: " + known_variant_list() + ")");
    if (count == 0) throw std::invalid_argument("chain item " + detail::quote(item) + " has no chips");
    if (out.size() + count > Chain::kMaxChips)
      throw std::invalid_argument("a chain has at most " + std::to_string(Chain::kMaxChips) + " chips");
    out.insert(out.end(), count, v);
  }
  if (out.empty()) throw std::invalid_argument("empty chain description (e.g. 3, 3*L6470 or L6470,L6480)");
  return out;
}

std::string chain_spec_of(std::span<const Variant* const> variants) {
  std::string out;
  for (std::size_t i = 0; i < variants.size();) {
    std::size_t j = i;
    while (j < variants.size() && variants[j] == variants[i]) ++j;
    if (!out.empty()) out += ',';
    if (j - i > 1) out += std::to_string(j - i) + "*";
    out += variants[i]->name;
    i = j;
  }
  return out;
}

std::string chain_spec_of(const Chain& chain) {
  std::vector<const Variant*> v;
  for (std::size_t i = 0; i < chain.size(); ++i) v.push_back(&chain.chip(i).variant());
  return chain_spec_of(v);
}

Chain make_chain(std::span<const Variant* const> variants, Quirks quirks) {
  std::vector<Chip> chips;
  chips.reserve(variants.size());
  for (const Variant* v : variants) chips.emplace_back(*v, quirks);
  return Chain(std::move(chips));
}

}  // namespace l6470emu
