// `l6470emu units`: register values and physical values both ways, with the variant's formulas.
#include "tools/cmd_units.hpp"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include "board/board_config.hpp"
#include "core/near_miss.hpp"
#include "core/units.hpp"
#include "tools/cli_errors.hpp"

namespace l6470emu {
namespace {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string hex(std::uint32_t v, unsigned bits) {
  char buf[80];
  std::snprintf(buf, sizeof buf, "0x%0*X", static_cast<int>((bits + 3) / 4), v);
  return buf;
}

std::string short_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.7g", v);
  return buf;
}

/// The register `name` names in `variant`'s tables (either reading of the powerSTEP01), or nullptr.
const RegisterInfo* register_named(const Variant& variant, std::string_view name) {
  for (const Variant* t : {&variant, variant.current_mode})
    if (t != nullptr)
      for (const RegisterInfo& r : t->registers)
        if (same_name(r.name, name)) return &r;
  return nullptr;
}

/// The scales that live in register `reg` (two for T_FAST).
std::vector<const UnitScale*> scales_in(const Variant& variant, Reg reg) {
  std::vector<const UnitScale*> out;
  for (const UnitScale& s : unit_scales(variant))
    if (s.reg == reg) out.push_back(&s);
  return out;
}

/// Register bits outside the scales that have a name of their own.
std::string flag_bits(const RegisterInfo& r, std::uint32_t value, std::uint32_t field_bits) {
  std::string out;
  for (unsigned b = 0; b < r.bits; ++b) {
    if ((field_bits >> b & 1u) != 0 || (value >> b & 1u) == 0) continue;
    std::string name = "bit " + std::to_string(b);
    if (r.id == Reg::MIN_SPEED && b == 12) name = "LSPD_OPT";
    if (r.id == Reg::FS_SPD && b == 10) name = "BOOST_MODE";
    out += ", " + name;
  }
  return out;
}

std::string physical_text(const UnitScale& s, std::uint32_t n) {
  const PhysicalValue p = to_physical(s, n);
  if (p.infinite) return "infinite acceleration (the moves have no ramps)";
  return p.decimal() + " " + std::string(unit_symbol(s.unit));
}

/// The lookup of `name` in `variant`, with the reason when there is no scale.
struct Lookup {
  const RegisterInfo* reg = nullptr;
  std::vector<const UnitScale*> scales;  // the register's fields, or the one field named
};

Lookup look_up(const Variant& variant, const std::string& name) {
  Lookup l;
  if (const UnitScale* s = find_unit_scale(variant, name)) {
    l.reg = register_named(variant, name);
    if (l.reg == nullptr)  // a field name (TOFF_FAST) or SPD
      for (const Variant* t : {&variant, variant.current_mode})
        if (t != nullptr && l.reg == nullptr) l.reg = t->find(s->reg);
    l.scales = {s};
    return l;
  }
  l.reg = register_named(variant, name);
  if (l.reg != nullptr) l.scales = scales_in(variant, l.reg->id);
  if (!l.scales.empty()) return l;  // T_FAST: its two fields
  const std::string why = why_no_unit_scale(variant, name);
  if (why.rfind("unknown register", 0) == 0)
    throw UsageError(why + " (l6470emu units --variant " + std::string(variant.name) + " lists them)");
  if (l.reg != nullptr)
    throw UsageError(why + " (l6470emu units --variant " + std::string(variant.name) + " lists the registers with one)");
  throw UsageError(why + "; --variant names the chip");
}

/// "0x041", "65", "0b1000001": a register value; nullopt when `text` is not an integer.
std::optional<std::uint64_t> register_value(const std::string& text) {
  int base = 10;
  std::string digits = text;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) base = 16, digits = text.substr(2);
  else if (text.size() > 2 && text[0] == '0' && (text[1] == 'b' || text[1] == 'B')) base = 2, digits = text.substr(2);
  if (digits.empty() || digits.size() > 16) return std::nullopt;
  for (char c : digits) {
    const bool ok = base == 16 ? std::isxdigit(static_cast<unsigned char>(c)) != 0
                    : base == 2 ? (c == '0' || c == '1')
                                : std::isdigit(static_cast<unsigned char>(c)) != 0;
    if (!ok) return std::nullopt;
  }
  return std::strtoull(digits.c_str(), nullptr, base);
}

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

/// A physical value in the scale's unit from "200step/s", "3.5 A", "16%", "4us".
double physical_value(const UnitScale& s, const std::string& text) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(begin, &end);
  if (end == begin || text.rfind("0x", 0) == 0 || text.rfind("0X", 0) == 0)
    throw UsageError("'" + text + "' is neither a register value (0x041, 65) nor a number with a unit (200step/s)");
  std::string unit = trimmed(end);
  const std::string expected(unit_symbol(s.unit));
  bool percent = false;
  if (!unit.empty() && unit[0] == '%') percent = true, unit = trimmed(unit.substr(1));
  struct Spelling {
    PhysicalUnit unit;
    const char* text;
    double multiply, divide;
  };
  static const Spelling kSpellings[] = {
      {PhysicalUnit::step_per_s, "step/s", 1, 1},    {PhysicalUnit::step_per_s, "steps/s", 1, 1},
      {PhysicalUnit::step_per_s2, "step/s²", 1, 1},  {PhysicalUnit::step_per_s2, "step/s^2", 1, 1},
      {PhysicalUnit::step_per_s2, "step/s2", 1, 1},  {PhysicalUnit::step_per_s2, "steps/s²", 1, 1},
      {PhysicalUnit::step_per_s2, "steps/s^2", 1, 1}, {PhysicalUnit::step_per_s2, "steps/s2", 1, 1},
      {PhysicalUnit::mA, "mA", 1, 1},                {PhysicalUnit::mA, "A", 1000, 1},
      {PhysicalUnit::mV, "mV", 1, 1},                {PhysicalUnit::mV, "V", 1000, 1},
      {PhysicalUnit::fraction_of_VS, "VS", 1, 1},    {PhysicalUnit::fraction_of_VREG, "VREG", 1, 1},
      {PhysicalUnit::s_per_step, "s/step", 1, 1},    {PhysicalUnit::us, "us", 1, 1},
      {PhysicalUnit::us, "µs", 1, 1},                {PhysicalUnit::us, "ns", 1, 1000},
      {PhysicalUnit::us, "ms", 1000, 1},             {PhysicalUnit::factor, "x", 1, 1},
  };
  if (percent && unit.empty() && (s.unit == PhysicalUnit::fraction_of_VS || s.unit == PhysicalUnit::fraction_of_VREG))
    return x / 100;
  if (unit.empty() && std::isinf(x) && !percent) return x;  // inf: infinite acceleration, whatever the unit
  if (unit.empty())
    throw UsageError("'" + text + "': give the unit (" + short_number(x) + expected +
                     ") or an integer register value (0x041)");
  for (const Spelling& sp : kSpellings)
    if (sp.unit == s.unit && unit == sp.text) return x * sp.multiply / sp.divide / (percent ? 100 : 1);
  throw UsageError(std::string(s.name) + " is in " + expected + ", not '" + (percent ? "%" : "") + unit + "'");
}

int convert(const Variant& variant, const UnitsArgs& a, std::ostream& out, std::ostream& err) {
  const Lookup l = look_up(variant, a.reg);
  const RegisterInfo& r = *l.reg;
  const std::string value = trimmed(a.value);
  for (const UnitScale* s : l.scales)
    if (!s->note.empty()) err << "note: " << variant.name << " " << s->name << ": " << s->note << "\n";
  if (const auto v = register_value(value)) {
    const bool field_only = l.scales.size() == 1 && !same_name(l.scales[0]->name, r.name) &&
                            !same_name(a.reg, "SPD");  // TOFF_FAST 0x1: the field's own value
    const unsigned bits = field_only ? l.scales[0]->bits : r.bits;
    if (*v >> bits != 0)
      throw UsageError(std::string(field_only ? l.scales[0]->name : r.name) + " has " + std::to_string(bits) +
                       " bits: " + value + " is above " + hex((1u << bits) - 1u, bits));
    const auto n = static_cast<std::uint32_t>(*v);
    out << (field_only ? l.scales[0]->name : r.name) << " " << hex(n, bits) << " (" << n << ") = ";
    if (field_only) {
      out << physical_text(*l.scales[0], n) << "\n";
      return 0;
    }
    std::uint32_t fields = 0;
    for (std::size_t i = 0; i < l.scales.size(); ++i) {
      const UnitScale& s = *l.scales[i];
      fields |= s.field_mask();
      if (l.scales.size() > 1) out << (i == 0 ? "" : ", ") << s.name << " ";
      out << physical_text(s, s.field_of(n));
    }
    out << flag_bits(r, n, fields) << "\n";
    return 0;
  }
  if (l.scales.size() > 1)
    throw UsageError(why_no_unit_scale(variant, r.name) + ": convert one at a time (or give a register value)");
  const UnitScale& s = *l.scales[0];
  const double x = physical_value(s, value);
  const FieldValue f = to_register(s, x, a.saturate ? OutOfRange::saturate : OutOfRange::refuse);
  if (!f.ok) throw UsageError(f.error);
  const std::string shown_input = std::isinf(x) ? (x > 0 ? "inf" : "-inf") : short_number(x);
  const PhysicalValue back = to_physical(s, f.n);
  const bool exact = back.to_double() == x;
  out << s.name << " " << shown_input << " " << unit_symbol(s.unit) << " -> " << hex(f.n, s.bits) << " (" << f.n
      << ")";
  if (s.shift != 0) out << " in bits " << s.shift + s.bits - 1 << ".." << unsigned{s.shift} << " of " << r.name;
  if (!exact) {
    const bool saturated = !to_register(s, x).ok;
    out << " = " << physical_text(s, f.n) << (saturated ? ", the nearest in range" : ", the nearest value");
  } else {
    out << " exactly";
  }
  out << "\n";
  return 0;
}

void describe(const Variant& variant, const UnitScale& s, std::ostream& out) {
  const std::uint32_t top = s.max_finite_field();
  out << s.name << ": " << describe_scale(variant, s) << ", " << to_physical(s, 0).decimal() << " … "
      << to_physical(s, top).decimal() << " " << unit_symbol(s.unit) << " (" << hex(0, s.bits) << " … "
      << hex(top, s.bits) << ")";
  if (s.top_is_infinite) out << "; " << hex(s.max_field(), s.bits) << " = infinite acceleration";
  out << "\n";
  if (!s.note.empty()) out << "  note: " << s.note << "\n";
}

}  // namespace

int run_units(const UnitsArgs& a, std::ostream& out, std::ostream& err) {
  try {
    const Variant* variant = lookup_variant(a.variant);
    if (variant == nullptr)
      throw UsageError("--variant: unknown chip variant '" + a.variant + "' (" + variant_suggestion(a.variant) +
                       "known: " + known_variant_list() + ")");
    if (a.reg.empty()) {
      out << "# " << variant->name << ": physical = formula of the register's value n\n";
      for (const UnitScale& s : unit_scales(*variant)) describe(*variant, s, out);
      return 0;
    }
    if (a.value.empty()) {
      for (const UnitScale* s : look_up(*variant, a.reg).scales) describe(*variant, *s, out);
      return 0;
    }
    return convert(*variant, a, out, err);
  } catch (const UsageError& e) {
    err << "l6470emu units: " << e.what() << "\n";
    return kUsageError;
  }
}

std::string units_table_markdown() {
  struct Row {
    std::string name, variants, value, range, note;
  };
  std::vector<Row> rows;
  for (const Variant* v : all_variants()) {
    for (const UnitScale& s : unit_scales(*v)) {
      const std::uint32_t top = s.max_finite_field();
      Row row{std::string(s.name), std::string(v->name), describe_scale(*v, s),
              short_number(to_physical(s, 0).to_double()) + " … " + short_number(to_physical(s, top).to_double()) + " " +
                  std::string(unit_symbol(s.unit)) +
                  (s.top_is_infinite ? "; " + hex(s.max_field(), s.bits) + " = infinite" : ""),
              std::string(s.note)};
      bool merged = false;
      for (Row& r : rows)
        if (r.name == row.name && r.value == row.value && r.range == row.range && r.note == row.note) {
          r.variants += ", " + row.variants;
          merged = true;
        }
      if (!merged) rows.push_back(row);
    }
  }
  std::string every;  // the list a row of every variant has
  for (const Variant* v : all_variants()) every += (every.empty() ? "" : ", ") + std::string(v->name);
  std::string out = "| Register | Variants | Physical value of n | Range | Source note |\n|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    const std::string variants = r.variants == every ? "all" : r.variants;
    out += "| " + r.name + " | " + variants + " | " + r.value + " | " + r.range + " | " + r.note + " |\n";
  }
  return out;
}

void add_units_command(CLI::App& app) {
  auto a = std::make_shared<UnitsArgs>();
  CLI::App* u = app.add_subcommand(
      "units", "register values in physical units and back: step/s, step/s², mA, mV, fractions of VS, s/step, µs "
               "(exit 2 = bad register, variant or value)");
  u->add_option("REGISTER", a->reg, "register (MAX_SPEED, OCD_TH, ...), a field (TOFF_FAST, FAST_STEP) or SPD; "
                                    "none: every register of the variant");
  u->add_option("VALUE", a->value,
                "a register value (0x041, 65) or a physical value with its unit (200step/s, '3.5 A', 16%, 4us, inf); "
                "none: the register's formula and range");
  u->add_option("--variant", a->variant, "the chip: L6470 (default), L6472, L6480, L6482, powerSTEP01, L6474");
  u->add_flag("--saturate", a->saturate, "a physical value out of range gives the nearest end instead of an error");
  u->callback([a] {
    const int status = run_units(*a, std::cout, std::cerr);
    if (status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace l6470emu
