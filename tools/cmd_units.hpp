// `l6470emu units REGISTER VALUE`: a register value in physical units, or a physical value as
// the register value nearest to it, per variant (core/units.hpp); the table of every scale.
#pragma once

#include <iosfwd>
#include <string>

namespace CLI {
class App;
}

namespace l6470emu {

struct UnitsArgs {
  std::string reg;                ///< register or field name; empty = every scale of the variant
  std::string value;              ///< "0x041", "65" (register values) or "200step/s", "3.5 A" (physical)
  std::string variant = "L6470";
  bool saturate = false;          ///< out-of-range physical values give the nearest end instead of an error
};

/// Runs `l6470emu units`: 0, or 2 with one line on `err` for a bad register, variant or value.
int run_units(const UnitsArgs& args, std::ostream& out, std::ostream& err);

/// The scales of every variant as a Markdown table (the README's generated block "units").
std::string units_table_markdown();

/// Adds `units` to `app`.
void add_units_command(CLI::App& app);

}  // namespace l6470emu
