// Python arguments into C++ values for the l6470emu module: bytes from anything with the
// buffer protocol (bytes, bytearray, memoryview, numpy uint8 arrays) or a sequence of ints,
// range-checked integers, chain descriptions, registers and enum-or-name arguments. Every
// mistake becomes a ValueError or TypeError naming the argument, never a crash.
#pragma once

#include <pybind11/pybind11.h>

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/chip.hpp"
#include "core/variant.hpp"
#include "spi/trace.hpp"

namespace l6470emu::python {

namespace py = pybind11;

/// The bytes of `data`: a one-dimensional buffer of 1-byte items (format B, b or c), or an
/// iterable of ints 0..255. `what` names the argument in error messages.
std::vector<std::uint8_t> bytes_from(py::handle data, const char* what);

/// Writes `bytes` into `out`, a writable one-dimensional buffer of 1-byte items of the same length.
void bytes_into(py::handle out, std::span<const std::uint8_t> bytes, const char* what);

/// An integer argument in [lo, hi]; TypeError when `value` is no int, ValueError when out of range.
long long int_in_range(py::handle value, const char* what, long long lo, long long hi);

/// A chain description from a str ("2xL6480,L6470", "3*L6470", "3"), a sequence of them, or a
/// number of L6470s.
std::string chain_spec_from(py::handle chips);

/// A filesystem path from a str or os.PathLike.
std::string path_from(py::handle path, const char* what);

/// The register `reg` names on `chip` (a Reg, its name, or an address 0x01..0x1F), checked
/// against the table in force. `chip_index` is for the message.
const RegisterInfo& register_from(const Chip& chip, std::size_t chip_index, py::handle reg);

/// A Thermal from the enum or its name ("warning"), or its number 0..3.
Thermal thermal_from(py::handle value);
/// A Bridge from the enum or "A"/"B".
Bridge bridge_from(py::handle value);
/// A TraceFault from the enum or its name ("OCD", case-insensitive).
TraceFault fault_from(py::handle value);

}  // namespace l6470emu::python
