// The text of an AxisSpec: the axis clause of the board description (axis.K=ITEM,ITEM,...) and
// of a native trace's `axis` events — a motor, its load, hard stops and switches behind one
// chip, in readable units, parsed into AxisSpec and written back. No OS calls;
// docs/linux.md lists the items.
#pragma once

#include <string>
#include <string_view>

#include "core/axis_spec.hpp"

namespace l6470emu {

/// Parses the value of an axis.K= word into `spec` (starting from `spec`'s values, so defaults
/// or an earlier spec carry over). Items are comma separated NAME=VALUE:
///   steps=200 torque=0.44 (N·m) current=1.7 (A) r=1.5 (Ω) l=2.8 (mH) rotor=57 (g·cm²)
///   load=0 (g·cm²) friction=0 (N·m) force=0 (N·m, signed) vs=12 (V) rds=0.016 (Ω) rsense=0.2 (Ω)
///   stops=LO..HI (either side may be empty) start=POS pullin=STEPS_PER_S
///   switch=NAME@POS[:below|above][:no|nc][:hyst=N][:bounce=COUNT/MICROSECONDS] (repeatable)
/// Positions are in 1/128 step (ABS_POS units at STEP_SEL = 7). Returns "" or what is wrong.
std::string parse_axis_spec(std::string_view text, AxisSpec& spec);

/// The items `spec` differs from the default in, as parse_axis_spec reads them back ("" when
/// it is the default; then the description writes `axis.K=default`).
std::string describe_axis_spec(const AxisSpec& spec);

/// Parses only the load items (load=, friction=, force=) into `load`, for `ctl axis load`.
std::string parse_axis_load(std::string_view text, LoadSpec& load);

}  // namespace l6470emu
