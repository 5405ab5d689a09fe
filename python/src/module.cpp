// The l6470emu._l6470emu extension module: the emulator for Python (bindings over daisychain/,
// spi/ traces and the tools' trace input). The package's __init__.py re-exports it.
#include "bindings.hpp"
#include "daisychain/motion_series.hpp"
#include "spi/trace.hpp"

PYBIND11_MODULE(_l6470emu, m) {
  m.doc() =
      "Register-level emulator of the ST L6470-family SPI stepper drivers (L6470, L6472, L6480,\n"
      "L6482, powerSTEP01, L6474): daisy chains in virtual time, byte-exact SPI, pins, faults, traces.";
  m.attr("__version__") = L6470EMU_VERSION;
  m.attr("TICKS_PER_SECOND") = 4'000'000;
  // The bounds on the work a trace may ask for (max_frames=, max_points=): spi/trace.hpp and
  // daisychain/motion_series.hpp hold them.
  m.attr("DEFAULT_MAX_FRAMES") = l6470emu::kDefaultMaxTraceFrames;
  m.attr("MAX_MOTION_POINTS") = l6470emu::kMaxMotionPoints;
  l6470emu::python::bind_registers(m);
  l6470emu::python::bind_chain(m);
  l6470emu::python::bind_trace(m);
  l6470emu::python::bind_motion(m);
  l6470emu::python::bind_units(m);
  l6470emu::python::bind_board(m);
  l6470emu::python::bind_coverage(m);
}
