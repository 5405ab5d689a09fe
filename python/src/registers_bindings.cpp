// Registers and the small enums of the l6470emu module: Reg holds every register name the
// variant tables use (powerSTEP01 current-mode names included), RegisterInfo is one table row.
#include <pybind11/stl.h>

#include <array>
#include <string>

#include "bindings.hpp"
#include "convert.hpp"
#include "core/near_miss.hpp"

namespace l6470emu::python {
namespace {

/// Every register id with the name the tables give it, in id order.
std::array<std::string, static_cast<std::size_t>(Reg::count)> register_names() {
  std::array<std::string, static_cast<std::size_t>(Reg::count)> names;
  auto take = [&](const Variant& v) {
    for (const RegisterInfo& r : v.registers) names[static_cast<std::size_t>(r.id)] = std::string(r.name);
  };
  for (const Variant* v : all_variants()) {
    take(*v);
    if (v->current_mode) take(*v->current_mode);
  }
  return names;
}

const Variant& variant_named(const std::string& name) {
  const Variant* v = find_variant(name);
  if (v == nullptr)
    throw py::value_error("unknown chip variant \"" + name + "\" (" + variant_suggestion(name) +
                          "known: " + known_variant_list() + ")");
  return *v;
}

}  // namespace

void bind_registers(py::module_& m) {
  py::enum_<Reg> reg(m, "Reg", "Every register of the family by datasheet name (a variant has a subset: "
                               "Chain.registers(chip) lists the table in force).");
  const auto names = register_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (!names[i].empty()) reg.value(names[i].c_str(), static_cast<Reg>(i));

  py::enum_<Thermal>(m, "Thermal", "Die temperature class (TH_WRN / TH_SD, or TH_STATUS on the gate-driver parts).")
      .value("normal", Thermal::normal)
      .value("warning", Thermal::warning)
      .value("bridge_shutdown", Thermal::bridge_shutdown)
      .value("device_shutdown", Thermal::device_shutdown);

  py::enum_<Bridge>(m, "Bridge", "The power bridge a stall is detected on.")
      .value("A", Bridge::A)
      .value("B", Bridge::B);

  py::enum_<TraceFault>(m, "Fault", "Backdoor events, as in a trace's fault lines (Chain.fault).")
      .value("UVLO", TraceFault::UVLO)
      .value("UVLO_ADC", TraceFault::UVLO_ADC)
      .value("OCD", TraceFault::OCD)
      .value("STALL_A", TraceFault::STALL_A)
      .value("STALL_B", TraceFault::STALL_B)
      .value("THERMAL", TraceFault::THERMAL)
      .value("ADCIN", TraceFault::ADCIN)
      .value("POWER_CYCLE", TraceFault::POWER_CYCLE)
      .value("MISO_FLIP", TraceFault::MISO_FLIP)
      .value("LOST_FRAME", TraceFault::LOST_FRAME);

  py::class_<RegisterInfo>(m, "RegisterInfo", "One row of a variant's register table.")
      .def_property_readonly("address", [](const RegisterInfo& r) { return r.address; }, "PARAM address 0x01..0x1F")
      .def_property_readonly("reg", [](const RegisterInfo& r) { return r.id; }, "the register as an l6470emu.Reg")
      .def_property_readonly("name", [](const RegisterInfo& r) { return std::string(r.name); }, "datasheet name")
      .def_property_readonly("bits", [](const RegisterInfo& r) { return r.bits; }, "width in bits")
      .def_property_readonly("spi_bytes", &RegisterInfo::spi_bytes, "bytes of the value on SPI")
      .def_property_readonly("reset", [](const RegisterInfo& r) { return r.reset; }, "value after power-up")
      .def_property_readonly("access", [](const RegisterInfo& r) { return std::string(to_string(r.access)); },
                             "write condition: R, WR (any time), WS (stopped), WH (bridges in HiZ)")
      .def_property_readonly("signed", &RegisterInfo::is_signed, "22-bit two's complement (ABS_POS, MARK)")
      .def_property_readonly("live", &RegisterInfo::is_live, "computed by the model (SPEED, STATUS, ...)")
      .def_property_readonly("unconfirmed", [](const RegisterInfo& r) { return (r.flags & kUnconfirmed) != 0; },
                             "width, reset or presence from a single non-datasheet source")
      .def("__repr__", [](const RegisterInfo& r) {
        char buf[128];
        std::snprintf(buf, sizeof buf, "RegisterInfo(0x%02X %s, %u bits, reset 0x%X, %s)", r.address,
                      std::string(r.name).c_str(), r.bits, r.reset, std::string(to_string(r.access)).c_str());
        return std::string(buf);
      });

  m.def(
      "variants",
      [] {
        std::vector<std::string> out;
        for (const Variant* v : all_variants()) out.emplace_back(v->name);
        return out;
      },
      "The chip variants by name: L6470, L6472, L6480, L6482, powerSTEP01, L6474.");
  m.def(
      "register_table",
      [](const std::string& variant, bool current_mode) {
        const Variant& v = variant_named(variant);
        if (current_mode && v.current_mode == nullptr)
          throw py::value_error(std::string(v.name) + " has no current-mode table (only the powerSTEP01 does)");
        const Variant& t = current_mode ? *v.current_mode : v;
        return std::vector<RegisterInfo>(t.registers.begin(), t.registers.end());
      },
      py::arg("variant"), py::arg("current_mode") = false,
      "The register table of a variant (the powerSTEP01's current-mode reading with current_mode=True).");
}

}  // namespace l6470emu::python
