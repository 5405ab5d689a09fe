// The pieces of the l6470emu Python module: each bind_*() adds one concern to it.
#pragma once

#include <pybind11/pybind11.h>

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
/// The private functions l6470emu.units is written over (register values <-> physical units).
void bind_units(py::module_& m);

}  // namespace l6470emu::python
