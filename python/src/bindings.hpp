// The pieces of the l6470emu Python module: each bind_*() adds one concern to it.
#pragma once

#include <pybind11/pybind11.h>

#include <string>

#include "core/chip.hpp"
#include "coverage_output.hpp"

namespace l6470emu::python {

namespace py = pybind11;

/// Reg (every register name of the variant tables), RegisterInfo, Thermal, Bridge, Fault,
/// variants() and register_table().
void bind_registers(py::module_& m);
/// Chain: frames, the reference host's commands, time, pins, faults, STATUS, recording.
void bind_chain(py::module_& m);
/// Trace, TraceEvent, TraceError, replay() and decode().
void bind_trace(py::module_& m);
/// motion() and its Motion, ChipMotion and CommandMark: what the chips of a trace did, as series.
void bind_motion(py::module_& m);
/// _BoardCore: a board description's board in virtual time in the test process (l6470emu.Board).
void bind_board(py::module_& m);
/// The axis behind `chip` as a dict (true position, lost steps, switches, ...); ValueError without one.
py::dict axis_state(const Chip& chip);
/// The axis spec the board description's axis items make for `chip` (an attached axis's spec,
/// with its rotor where it is now, is the start); ValueError for a bad item. The caller attaches
/// it (recorded where it records).
AxisSpec axis_from_text(const Chip& chip, const std::string& text);
/// The attached axis's load with the items of `text` (load=, friction=, force=) changed;
/// ValueError without an axis or for a bad item. The caller applies it (recorded where it records).
LoadSpec load_from_text(const Chip& chip, const std::string& text);
/// coverage_report(), coverage_total(), and the merge of every live object's coverage at exit.
void bind_coverage(py::module_& m);
/// What a coverage= argument asks for: None (the file L6470EMU_COVERAGE names, when set; else
/// nothing), False (nothing), True (collected in memory only), or a path (made absolute).
/// ValueError with one line when the file cannot take coverage (check_coverage_output).
CoverageRequest coverage_request_from(py::handle arg);
/// `data` as a dict: the coverage file's JSON structure.
py::object coverage_dict(const CoverageData& data);
/// The private functions l6470emu.units is written over (register values <-> physical units).
void bind_units(py::module_& m);

}  // namespace l6470emu::python
