// The list of family members and look-up by name.
#include <array>
#include <cctype>

#include "core/variant.hpp"

namespace l6470emu {

bool same_name(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  return true;
}

std::span<const Variant* const> all_variants() {
  static const std::array<const Variant*, 6> kAll{&l6470(), &l6472(), &l6480(), &l6482(), &powerstep01(), &l6474()};
  return kAll;
}

const Variant* find_variant(std::string_view name) {
  for (const Variant* v : all_variants())
    if (same_name(v->name, name)) return v;
  return nullptr;
}

}  // namespace l6470emu
