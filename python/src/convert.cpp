// Argument conversion for the l6470emu module (see convert.hpp).
#include "convert.hpp"

#include <pybind11/stl.h>

#include <cctype>
#include <string_view>

#include "daisychain/chain_spec.hpp"

namespace l6470emu::python {
namespace {


// A 1-byte item format: "B", "b", "c", optionally with a byte-order character.
bool byte_format(const std::string& f) {
  std::string_view s = f;
  if (!s.empty() && (s[0] == '@' || s[0] == '=' || s[0] == '<' || s[0] == '>' || s[0] == '!')) s.remove_prefix(1);
  return s == "B" || s == "b" || s == "c";
}

py::buffer_info byte_buffer(py::handle data, bool writable, const char* what) {
  py::buffer_info info = py::reinterpret_borrow<py::buffer>(data).request(writable);
  if (info.itemsize != 1 || !byte_format(info.format))
    throw py::value_error(std::string(what) + ": a buffer of bytes is needed (item format 'B'), not items of format '" +
                          info.format + "' and size " + std::to_string(info.itemsize) +
                          " (for a numpy array: .astype(numpy.uint8))");
  if (info.ndim != 1)
    throw py::value_error(std::string(what) + ": a one-dimensional buffer is needed, not " + std::to_string(info.ndim) +
                          " dimensions");
  return info;
}

}  // namespace

std::vector<std::uint8_t> bytes_from(py::handle data, const char* what) {
  if (PyObject_CheckBuffer(data.ptr())) {
    const py::buffer_info info = byte_buffer(data, false, what);
    std::vector<std::uint8_t> out(static_cast<std::size_t>(info.shape[0]));
    const auto* base = static_cast<const std::uint8_t*>(info.ptr);
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = base[static_cast<py::ssize_t>(i) * info.strides[0]];
    return out;
  }
  if (py::isinstance<py::str>(data))
    throw py::type_error(std::string(what) + ": a str is not bytes (use b\"...\", bytes.fromhex() or .encode())");
  if (!py::isinstance<py::iterable>(data))
    throw py::type_error(std::string(what) + ": bytes, bytearray, memoryview, a numpy uint8 array or a list of ints is needed, not " +
                         std::string(py::str(py::type::handle_of(data).attr("__name__"))));
  std::vector<std::uint8_t> out;
  std::size_t i = 0;
  for (py::handle item : data) {
    const std::string where = std::string(what) + "[" + std::to_string(i++) + "]";
    out.push_back(static_cast<std::uint8_t>(int_in_range(item, where.c_str(), 0, 255)));
  }
  return out;
}

void bytes_into(py::handle out, std::span<const std::uint8_t> bytes, const char* what) {
  if (!PyObject_CheckBuffer(out.ptr()))
    throw py::type_error(std::string(what) + ": a writable buffer (bytearray, memoryview, numpy uint8 array) is needed");
  py::buffer_info info;
  try {
    info = byte_buffer(out, true, what);
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_BufferError) && !e.matches(PyExc_TypeError)) throw;
    throw py::type_error(std::string(what) + ": the buffer is read-only (use a bytearray or a writable array)");
  }
  if (static_cast<std::size_t>(info.shape[0]) != bytes.size())
    throw py::value_error(std::string(what) + ": holds " + std::to_string(info.shape[0]) + " bytes, the frame has " +
                          std::to_string(bytes.size()));
  auto* base = static_cast<std::uint8_t*>(info.ptr);
  for (std::size_t i = 0; i < bytes.size(); ++i) base[static_cast<py::ssize_t>(i) * info.strides[0]] = bytes[i];
}

long long int_in_range(py::handle value, const char* what, long long lo, long long hi) {
  if (!PyLong_Check(value.ptr()))
    throw py::type_error(std::string(what) + ": an int is needed, not " +
                         std::string(py::str(py::type::handle_of(value).attr("__name__"))));
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(value.ptr(), &overflow);
  if (v == -1 && PyErr_Occurred()) throw py::error_already_set();
  if (overflow != 0 || v < lo || v > hi)
    throw py::value_error(std::string(what) + " = " + std::string(py::str(value)) + " is out of range " +
                          std::to_string(lo) + ".." + std::to_string(hi));
  return v;
}

std::string chain_spec_from(py::handle chips) {
  if (py::isinstance<py::str>(chips)) return chips.cast<std::string>();
  if (PyLong_Check(chips.ptr()) && !PyBool_Check(chips.ptr()))
    return std::to_string(int_in_range(chips, "chips", 1, 256));  // that many L6470s
  if (!py::isinstance<py::sequence>(chips))
    throw py::type_error("chips: a list of chip variants (\"L6470\", \"2xL6480\") or one string is needed");
  std::string spec;
  for (py::handle item : chips) {
    if (!py::isinstance<py::str>(item))
      throw py::type_error("chips: every item is a variant name (\"L6470\") or a count and a name (\"2xL6480\")");
    const std::string s = item.cast<std::string>();
    if (s.find_first_of(", \t") != std::string::npos)
      throw py::value_error("chips: \"" + s + "\" is not one item (give a list, or one comma-separated string)");
    if (!spec.empty()) spec += ',';
    spec += s;
  }
  if (spec.empty()) throw py::value_error("chips: a chain has at least one chip");
  return spec;
}

std::string path_from(py::handle path, const char* what) {
  py::object p;
  try {
    p = py::module_::import("os").attr("fspath")(path);
  } catch (py::error_already_set&) {
    throw py::type_error(std::string(what) + ": a path (str or os.PathLike) is needed");
  }
  if (!py::isinstance<py::str>(p)) throw py::type_error(std::string(what) + ": a str path is needed, not bytes");
  return p.cast<std::string>();
}

const RegisterInfo& register_from(const Chip& chip, std::size_t chip_index, py::handle reg) {
  const Variant& table = chip.registers();
  const RegisterInfo* r = nullptr;
  std::string asked;
  if (py::isinstance<Reg>(reg)) {
    const Reg id = reg.cast<Reg>();
    r = table.find(id);
    asked = std::string(py::str(reg.attr("name")));
  } else if (py::isinstance<py::str>(reg)) {
    asked = reg.cast<std::string>();
    for (const RegisterInfo& row : table.registers)
      if (same_name(row.name, asked)) r = &row;
    if (r == nullptr) {
      // A register of another variant (or mode) is "no such register here"; anything else is unknown.
      bool known = false;
      for (const Variant* v : all_variants()) {
        for (const RegisterInfo& row : v->registers) known = known || same_name(row.name, asked);
        if (v->current_mode)
          for (const RegisterInfo& row : v->current_mode->registers) known = known || same_name(row.name, asked);
      }
      if (!known) throw py::value_error("unknown register \"" + asked + "\" (see l6470emu.Reg for the names)");
    }
  } else if (PyLong_Check(reg.ptr())) {
    const auto address = static_cast<std::uint8_t>(int_in_range(reg, "register address", 0x01, 0x1F));
    r = table.at_address(address);
    if (r == nullptr)
      throw py::value_error("chip " + std::to_string(chip_index) + " (" + std::string(table.name) +
                            ") has no register at address " + std::to_string(address));
    return *r;
  } else {
    throw py::type_error("reg: an l6470emu.Reg, a register name or an address is needed");
  }
  if (r == nullptr)
    throw py::value_error("chip " + std::to_string(chip_index) + " (" + std::string(table.name) + ") has no register " +
                          asked);
  return *r;
}

Thermal thermal_from(py::handle value) {
  if (py::isinstance<Thermal>(value)) return value.cast<Thermal>();
  if (py::isinstance<py::str>(value)) {
    const std::string s = value.cast<std::string>();
    for (std::uint8_t t = 0; t < 4; ++t)
      if (same_name(thermal_name(t), s)) return static_cast<Thermal>(t);
    throw py::value_error("thermal: \"" + s + "\" is not normal, warning, bridge_shutdown or device_shutdown");
  }
  return static_cast<Thermal>(int_in_range(value, "thermal", 0, 3));
}

Bridge bridge_from(py::handle value) {
  if (py::isinstance<Bridge>(value)) return value.cast<Bridge>();
  if (py::isinstance<py::str>(value)) {
    const std::string s = value.cast<std::string>();
    if (same_name(s, "A")) return Bridge::A;
    if (same_name(s, "B")) return Bridge::B;
    throw py::value_error("bridge: \"" + s + "\" is not A or B");
  }
  throw py::type_error("bridge: l6470emu.Bridge.A/B or \"A\"/\"B\" is needed");
}

TraceFault fault_from(py::handle value) {
  if (py::isinstance<TraceFault>(value)) return value.cast<TraceFault>();
  if (py::isinstance<py::str>(value)) {
    const std::string s = value.cast<std::string>();
    for (unsigned f = 0; f < kTraceFaultCount; ++f)
      if (same_name(to_string(static_cast<TraceFault>(f)), s)) return static_cast<TraceFault>(f);
    throw py::value_error("fault: \"" + s +
                          "\" is not UVLO, UVLO_ADC, OCD, STALL_A, STALL_B, THERMAL, ADCIN, POWER_CYCLE, MISO_FLIP or "
                          "LOST_FRAME");
  }
  throw py::type_error("fault: an l6470emu.Fault or its name is needed");
}

}  // namespace l6470emu::python
