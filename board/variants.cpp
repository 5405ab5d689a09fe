// Variant names as the config and the ctl interface spell them: core's table, plus aliases.
#include <string>

#include "board/board_config.hpp"
#include "core/near_miss.hpp"

namespace l6470emu {

const Variant* lookup_variant(std::string_view name) {
  // Aliases users write for the same part; extend here when a new spelling shows up.
  if (name == "powerstep" || name == "powerSTEP") name = "powerSTEP01";
  return find_variant(name);
}

std::string known_variant_names() { return known_variant_list(); }

}  // namespace l6470emu
