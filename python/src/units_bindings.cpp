// The physical units of register values for Python (core/units.hpp): the private functions the
// l6470emu.units module is written over. Errors are ValueError with the C++ side's one line.
#include <pybind11/stl.h>

#include <cmath>
#include <tuple>

#include "bindings.hpp"
#include "convert.hpp"
#include "core/near_miss.hpp"
#include "core/units.hpp"

namespace l6470emu::python {
namespace {

const Variant& variant_called(const std::string& name) {
  const Variant* v = find_variant(name);
  if (v == nullptr && (name == "powerstep" || name == "powerSTEP")) v = &powerstep01();
  if (v == nullptr)
    throw py::value_error("variant: unknown chip variant \"" + name + "\" (" + variant_suggestion(name) +
                          "known: " + known_variant_list() + ")");
  return *v;
}

const UnitScale& scale_called(const std::string& variant, const std::string& name) {
  const Variant& v = variant_called(variant);
  const UnitScale* s = find_unit_scale(v, name);
  if (s == nullptr) throw py::value_error(why_no_unit_scale(v, name));
  return *s;
}

/// (name, register, shift, bits, offset_halves, lsb_num, lsb_den, unit, top_is_infinite, note)
using ScaleTuple = std::tuple<std::string, std::string, unsigned, unsigned, unsigned, std::uint64_t, std::uint64_t,
                              std::string, bool, std::string>;

ScaleTuple tuple_of(const Variant& v, const UnitScale& s) {
  std::string reg;
  for (const Variant* t : {&v, v.current_mode})
    if (t != nullptr && reg.empty())
      if (const RegisterInfo* r = t->find(s.reg)) reg = std::string(r->name);
  return {std::string(s.name), reg,   s.shift, s.bits, s.offset_halves, s.lsb_num, s.lsb_den,
          std::string(unit_symbol(s.unit)), s.top_is_infinite, std::string(s.note)};
}

}  // namespace

void bind_units(py::module_& m) {
  m.def(
      "_unit_scales",
      [](const std::string& variant) {
        const Variant& v = variant_called(variant);
        std::vector<ScaleTuple> out;
        for (const UnitScale& s : unit_scales(v)) out.push_back(tuple_of(v, s));
        return out;
      },
      py::arg("variant"), "Every scale of a variant as tuples (l6470emu.units.scales() is the public face).");
  m.def(
      "_unit_scale",
      [](const std::string& variant, const std::string& name) {
        return tuple_of(variant_called(variant), scale_called(variant, name));
      },
      py::arg("variant"), py::arg("name"), "One scale as a tuple (l6470emu.units.scale() is the public face).");
  m.def(
      "_to_physical",
      [](const std::string& variant, const std::string& name, py::handle value) {
        const UnitScale& s = scale_called(variant, name);
        const std::string what = std::string(s.name) + " value";  // "MAX_SPEED value = 1024 is out of range 0..1023"
        const long long n = int_in_range(value, what.c_str(), 0, s.max_field());
        const PhysicalValue p = to_physical(s, static_cast<std::uint32_t>(n));
        return std::make_tuple(p.num, p.den, p.infinite);
      },
      py::arg("variant"), py::arg("name"), py::arg("value"),
      "A field value's physical value as (numerator, denominator, infinite).");
  m.def(
      "_to_register",
      [](const std::string& variant, const std::string& name, double physical, bool saturate) {
        const FieldValue f =
            to_register(scale_called(variant, name), physical, saturate ? OutOfRange::saturate : OutOfRange::refuse);
        if (!f.ok) throw py::value_error(f.error);
        return f.n;
      },
      py::arg("variant"), py::arg("name"), py::arg("physical"), py::arg("saturate"),
      "The field value nearest to a physical value (ValueError out of range unless saturate).");
}

}  // namespace l6470emu::python
