// What the motors did, for Python: l6470emu.motion() replays a trace (a Trace or any file the
// l6470emu program reads) through a fresh emulated chain and returns each chip's ABS_POS,
// SPEED, MOT_STATUS, BUSY/FLAG/SW/HiZ series and command marks (daisychain/motion_series.hpp).
// Values stay in the datasheet's integer units; l6470emu.plot converts and draws them.
#include <pybind11/stl.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>

#include "bindings.hpp"
#include "core/counted.hpp"
#include "convert.hpp"
#include "trace_source.hpp"
#include "daisychain/chain_spec.hpp"
#include "daisychain/motion_series.hpp"
#include "spi/trace_import.hpp"
#include "tools/progress.hpp"
#include "tools/trace_input.hpp"

namespace l6470emu::python {
namespace {

/// One chip's series as Python lists (the plot module makes arrays of them).
struct PyChipMotion {
  std::size_t chip = 0;
  std::size_t number = 0;
  std::string variant;
  unsigned microsteps_per_step = 0;
  std::vector<Tick> ticks;
  std::vector<std::int32_t> abs_pos, speed;
  std::vector<int> mot_status;
  std::vector<bool> busy, flag, sw, hiz;
  std::vector<CommandMark> commands;
  std::uint64_t commands_dropped = 0;
};

struct PyMotion {
  Tick start = 0, end = 0, trace_end = 0;
  std::string chain, how, number_from = "miso", numbering, overridden;
  std::vector<PyChipMotion> chips;
  std::optional<FirstDivergence> divergence;  // none: the emulator reproduced what was read
  std::uint64_t frames_diverged = 0, pins_diverged = 0;
};

PyChipMotion chip_of(ChipMotion&& m) {
  PyChipMotion p;
  p.chip = m.chip;
  p.number = m.number;
  p.variant = std::move(m.variant);
  p.microsteps_per_step = m.microsteps_per_step;
  const std::size_t n = m.samples.size();
  p.ticks.reserve(n);
  for (const MotionSample& s : m.samples) {
    p.ticks.push_back(s.tick);
    p.abs_pos.push_back(s.abs_pos);
    p.speed.push_back(s.speed);
    p.mot_status.push_back(s.mot_status);
    p.busy.push_back(s.busy);
    p.flag.push_back(s.flag);
    p.sw.push_back(s.sw);
    p.hiz.push_back(s.hiz);
  }
  p.commands = std::move(m.commands);
  p.commands_dropped = m.commands_dropped;
  return p;
}

/// Seconds (a float or int >= 0) as the nearest tick; None = `none`.
Tick tick_from_seconds(py::handle seconds, const char* what, Tick none) {
  if (seconds.is_none()) return none;
  if (!py::isinstance<py::float_>(seconds) && !(PyLong_Check(seconds.ptr()) && !PyBool_Check(seconds.ptr())))
    throw py::type_error(std::string(what) + ": seconds (a float) are needed");
  const double s = seconds.cast<double>();
  if (!std::isfinite(s) || s < 0 || s > 1e9)
    throw py::value_error(std::string(what) + " = " + std::string(py::str(seconds)) + " is not a time in seconds from 0 to 1e9");
  return static_cast<Tick>(std::llround(s * static_cast<double>(kTicksPerSecond)));
}

/// A Python progress(stage, done, total, unit) told how far motion()'s passes have come, from
/// the thread running them without the GIL: at most every 100 ms (taking the GIL only then),
/// and always when a pass begins and ends. An exception it raises (KeyboardInterrupt) ends
/// motion() with it.
class PyProgress {
 public:
  explicit PyProgress(py::handle callback) : callback_(callback) {}
  /// The daisychain callback for one pass ("reading", "replaying"); empty without a callback.
  PassProgress pass(const char* stage) {
    if (callback_.is_none()) return {};
    return [this, stage, first = true](const ReadProgress& p) mutable {
      const auto now = std::chrono::steady_clock::now();
      const bool last = p.total != 0 && p.done == p.total;
      if (!first && !last && now - drawn_ < std::chrono::milliseconds(100)) return;
      first = false;
      drawn_ = now;
      py::gil_scoped_acquire locked;
      callback_(stage, p.done, p.total, p.bytes ? "bytes" : "events");
    };
  }

 private:
  py::handle callback_;  // motion()'s argument: alive (and referenced) for the whole call
  std::chrono::steady_clock::time_point drawn_{};
};

}  // namespace

void bind_motion(py::module_& m) {
  py::class_<CommandMark>(m, "CommandMark", "A command a chip decoded: when it acted (its frame's CS rising edge).")
      .def_readonly("tick", &CommandMark::tick, "the frame's CS rising edge, 250 ns ticks")
      .def_property_readonly("seconds", [](const CommandMark& c) { return static_cast<double>(c.tick) / kTicksPerSecond; },
                             "the same in seconds")
      .def_readonly("opcode", &CommandMark::opcode, "the opcode byte")
      .def_readonly("name", &CommandMark::name, "the command as the datasheet names it: \"Move(FWD)\", \"SoftStop\"")
      .def_readonly("text", &CommandMark::text, "with its argument: \"Move(FWD, 3200 microsteps)\"")
      .def("__repr__", [](const CommandMark& c) { return "CommandMark(" + std::to_string(c.tick) + ", " + c.text + ")"; });

  py::class_<PyChipMotion>(m, "ChipMotion", R"(One chip's series, sampled where they change: lists of equal length,
in the datasheet's units (ABS_POS in microsteps of the STEP_SEL in force, SPEED in 2^-28 full
step per tick, negative in reverse; pins as levels, False = pulled low).)")
      .def_readonly("chip", &PyChipMotion::chip, "the chip's index in the chain (0 drives MISO)")
      .def_readonly("number", &PyChipMotion::number, "the chip's number as motion()'s number_from counts (to show)")
      .def_readonly("variant", &PyChipMotion::variant, "\"L6470\", ...")
      .def_readonly("microsteps_per_step", &PyChipMotion::microsteps_per_step, "of the STEP_SEL in force at the end")
      .def_readonly("ticks", &PyChipMotion::ticks, "sample times, 250 ns ticks")
      .def_readonly("abs_pos", &PyChipMotion::abs_pos, "ABS_POS, microsteps")
      .def_readonly("speed", &PyChipMotion::speed, "SPEED register, signed by the direction (2^-28 step/tick); an L6474's step rate in the same units")
      .def_readonly("mot_status", &PyChipMotion::mot_status, "0 stopped, 1 accelerating, 2 decelerating, 3 constant speed")
      .def_readonly("busy", &PyChipMotion::busy, "BUSY pin level (False = busy)")
      .def_readonly("flag", &PyChipMotion::flag, "FLAG pin level (False = an enabled alarm)")
      .def_readonly("sw", &PyChipMotion::sw, "SW pin level (False = switch closed)")
      .def_readonly("hiz", &PyChipMotion::hiz, "bridges in high impedance")
      .def_readonly("commands", &PyChipMotion::commands, "the commands decoded in the window (NOP, GetParam, GetStatus left out)")
      .def_readonly("commands_dropped", &PyChipMotion::commands_dropped, "commands beyond max_commands, not listed")
      .def("__len__", [](const PyChipMotion& c) { return c.ticks.size(); })
      .def("__repr__", [](const PyChipMotion& c) {
        return "ChipMotion(chip " + std::to_string(c.number) + " " + c.variant + ", " + counted(c.ticks.size(), "sample") +
               ", " + counted(c.commands.size(), "command") + ")";
      });

  py::class_<PyMotion>(m, "Motion", "What the chips of a trace did over a window: .chips holds a ChipMotion per chip asked for.")
      .def_readonly("start", &PyMotion::start, "the window's first tick")
      .def_readonly("end", &PyMotion::end, "the window's last tick (open windows: where the motion ended)")
      .def_readonly("trace_end", &PyMotion::trace_end, "the trace's last event")
      .def_readonly("chain", &PyMotion::chain, "the emulated chain, chip 0 first (\"3*L6470\")")
      .def_readonly("how", &PyMotion::how, "where the chain came from, in words")
      .def_readonly("chips", &PyMotion::chips, "one ChipMotion per chip asked for")
      .def_readonly("number_from", &PyMotion::number_from, "how chip numbers count: \"miso\" or \"mosi\"")
      .def_readonly("numbering", &PyMotion::numbering, "what the chip numbers mean, in words")
      .def_readonly("divergence", &PyMotion::divergence,
                    "None when the emulator gave every captured MISO byte and BUSY/FLAG level read (up to the "
                    "window's end); else where it first did not (a FirstDivergence): from there on the series "
                    "are the emulator's model, not the capture, and plot() marks it")
      .def_readonly("frames_diverged", &PyMotion::frames_diverged, "frames read whose captured MISO the emulator does not give")
      .def_readonly("pins_diverged", &PyMotion::pins_diverged, "BUSY/FLAG observations read that the emulator does not reproduce")
      .def_readonly("overridden", &PyMotion::overridden,
                    "\"\" or a sentence saying that chain=/board= replaced the trace's own description")
      .def("__repr__", [](const PyMotion& p) {
        return "Motion(chain " + p.chain + ", " + counted(p.chips.size(), "chip") + ", ticks " +
               std::to_string(p.start) + ".." + std::to_string(p.end) + (p.divergence ? ", DIVERGED" : "") + ")";
      });

  m.def(
      "motion",
      [](py::handle trace, py::handle chain, py::handle format, std::string select, py::handle chips, py::handle start,
         py::handle end, py::handle max_points, std::size_t max_commands, const std::string& number_from,
         py::handle progress, py::handle max_frames, py::handle board) {
        if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
          throw py::type_error("progress: a function progress(stage, done, total, unit), or None");
        PyProgress told(progress);
        MotionOptions o;
        try {
          o.number_from = parse_number_from(number_from);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(std::string("number_from: ") + e.what());
        }
        o.from = tick_from_seconds(start, "start", 0);
        o.to = tick_from_seconds(end, "end", kNever);
        o.max_points = static_cast<std::size_t>(
            int_in_range(max_points, "max_points", 0, static_cast<long long>(kMaxMotionPoints)));
        o.max_commands = max_commands;
        if (!chips.is_none()) {
          if (!py::isinstance<py::sequence>(chips) || py::isinstance<py::str>(chips))
            throw py::type_error("chips: a list of chip numbers (counted as number_from says) is needed");
          for (py::handle c : chips) o.chips.push_back(static_cast<std::size_t>(int_in_range(c, "chips", 0, 255)));
          if (o.chips.empty()) throw py::value_error("chips: the list is empty (None = every chip)");
        }
        PyMotion result;
        result.number_from = to_string(o.number_from);
        result.numbering = describe_numbering(o.number_from);
        const Source source = source_of(trace, chain, format, select, max_frames_arg(max_frames), board);
        result.how = source.world.how;
        result.overridden = source.world.override_note(source.trace ? source.trace->header.name : source.file->path());
        {
          py::gil_scoped_release unlocked;
          Chain c = source.world.make_chain();
          result.chain = source.world.summary();
          Tick trace_end = 0;
          {
            auto pass = source.reader();
            trace_end = trace_end_tick(*pass, told.pass("reading"));
          }
          o.progress = told.pass("replaying");
          auto pass = source.reader();
          MotionSeries s = sample_motion(*pass, c, trace_end, o);
          result.start = s.from;
          result.end = s.to;
          result.trace_end = s.trace_end;
          for (ChipMotion& cm : s.chips) result.chips.push_back(chip_of(std::move(cm)));
          if (s.divergence.found) result.divergence = s.divergence;
          result.frames_diverged = s.frames_diverged;
          result.pins_diverged = s.pins_diverged;
        }
        return result;
      },
      py::arg("trace"), py::arg("chain") = py::none(), py::kw_only(), py::arg("format") = py::none(),
      py::arg("select") = "", py::arg("chips") = py::none(), py::arg("start") = py::none(), py::arg("end") = py::none(),
      py::arg("max_points") = 4000, py::arg("max_commands") = 2000, py::arg("number_from") = "miso",
      py::arg("progress") = py::none(), py::arg("max_frames") = kDefaultMaxTraceFrames, py::arg("board") = py::none(),
      R"(Replays a trace through a fresh emulated chain and samples what each chip did.

trace: a Trace (Chain(record=True).trace, Trace.load()) or a file in any format the l6470emu
program reads. chain: the chain (default: the trace's own description; for a file without one,
guessed from its frame lengths): variants ("3*L6470") or the board description of one chain
("chips=L6470 axis.0=stops=0..256000,switch=home@0"); board: instead, the path of a file holding
such a description (a capture from a rig with a switch or a loaded axis runs through the same
world). The result's divergence says where the emulator first gave MISO bytes or a BUSY/FLAG
level other than the trace's: from there on the series are its model, not the capture. chips: chip numbers to sample (default all), counted from the MISO
end (number_from="miso", chip 0 drives MISO) or the MOSI end ("mosi"). start, end: the window
in seconds from the trace's start (end None: the trace's end, plus up to 1 s while a move is
still going). Samples are the chips' exact states at their ticks: at the window's edges,
after every event that touches a chip, at every change of the motion rule (the ends of
acceleration, constant speed and deceleration: MOT_STATUS and BUSY edges to the tick) and
on a grid of about max_points / 4 steps; long runs are thinned to at most max_points per
chip (at most 100000, ValueError beyond; fewer than 64 are taken as 64). max_frames: the most frames a trace file may hold
(native repeat lines counted as the frames they stand for; 0: no limit): a file asking for
more raises TraceError at once. progress, if given, is called as progress(stage, done, total, unit) while the trace is
read ("reading": finding its end) and replayed ("replaying"): done and total count "bytes" of
the file or "events" (total 0: not known), done never goes back within a stage, and each
stage ends with done == total; at most about 10 calls a second (format_progress() draws a
bar of them). Raises ValueError for chips outside the chain or an empty window, TraceError for
malformed traces.)");

  m.def("format_progress",
        [](std::string_view label, std::uint64_t done, std::uint64_t total, std::string_view unit, std::size_t width) {
          return format_progress(label, done, total, unit, width);
        },
        py::arg("label"), py::arg("done"), py::arg("total"), py::arg("unit"),
        py::arg("width") = 80,
        R"(One line of progress, width characters at most, as the l6470emu program draws it on a
terminal: "replaying run.trace [#####-----]  50% 12.0 of 24.0 MB". unit "bytes" is shown in
kB/MB/GB, anything else as numbers; total 0: what was done, no bar.)");
}

}  // namespace l6470emu::python
