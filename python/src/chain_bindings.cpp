// l6470emu.Chain: a daisy chain for Python. Byte-level frames, the reference host's commands
// (daisychain/host.hpp), virtual time, the physical world (pins, ADC, faults: core/chip.hpp's
// backdoor), STATUS decoded by core/status.hpp, and recording into a native trace.
#include <pybind11/stl.h>

#include <cmath>
#include <string>

#include "bindings.hpp"
#include "convert.hpp"
#include "daisychain/chain_spec.hpp"
#include "py_chain.hpp"
#include "sanitizer_failure.hpp"

namespace l6470emu::python {
namespace {

constexpr long long kMax22 = (1LL << 22) - 1;  // n_step, abs_pos fields
constexpr long long kMax20 = (1LL << 20) - 1;  // speed fields

std::size_t chip_arg(const PyChain& c, py::handle k) {
  const long long n = static_cast<long long>(c.chain().size());
  if (PyLong_Check(k.ptr())) {
    int overflow = 0;
    const long long v = PyLong_AsLongLongAndOverflow(k.ptr(), &overflow);
    if (!PyErr_Occurred() && overflow == 0 && v >= 0 && v < n) return static_cast<std::size_t>(v);
    PyErr_Clear();
    throw py::value_error("chip " + std::string(py::str(k)) + " is not in the chain: it has " + std::to_string(n) +
                          (n == 1 ? " chip (0)" : " chips (0.." + std::to_string(n - 1) + ")"));
  }
  throw py::type_error("chip: an int index is needed (0 drives MISO)");
}

CheckConfig check_config_from(py::object level, py::object allow) {
  CheckConfig cc;
  if (!py::isinstance<py::str>(level)) throw py::type_error("check: \"off\", \"warn\" or \"error\"");
  std::string why;
  const auto l = parse_check_level(std::string(py::str(level)), why);
  if (!l) throw py::value_error("check " + why);
  cc.level = *l;
  if (py::isinstance<py::str>(allow)) throw py::type_error("check_allow: a list of rule names, not one string");
  for (py::handle item : allow) {
    if (!py::isinstance<py::str>(item)) throw py::type_error("check_allow: rule names are strings");
    const auto rules = parse_rule_list(std::string(py::str(item)), why);
    if (!rules) throw py::value_error("check_allow " + why);
    for (const RuleInfo& r : rule_table())
      if (rules->contains(r.rule)) cc.allowed.insert(r.rule);
  }
  return cc;
}

py::object make_status(const Chip& chip, std::uint16_t value) {
  return py::module_::import("l6470emu._status")
      .attr("Status")(value, describe_status(chip.status_layout(), value), std::string(chip.variant().name));
}

// A 22-bit two's complement position: -2^21..2^22-1 (values from 2^21 on are the raw field).
std::int32_t position_arg(py::handle v, const char* what) {
  return static_cast<std::int32_t>(int_in_range(v, what, -(1LL << 21), kMax22));
}

/// The sanitizer after SPI traffic: check=warn lines become l6470emu.SanitizerWarning warnings,
/// a check=error failure raises l6470emu.SanitizerError with the report.
void after_spi(PyChain& p) {
  p.look();  // interface coverage: the flags the traffic raised
  warn_sanitizer_lines(p.take_check_lines());
  if (auto report = p.take_check_failure()) throw SanitizerFailure(*report);
}

/// close(): the recording ends, the coverage met so far goes into its file.
void close_chain(PyChain& p) {
  p.close();
  if (const std::string why = p.flush_coverage(); !why.empty())
    throw std::runtime_error("l6470emu: coverage not written: " + why);
}

std::uint8_t level_arg(py::handle v, const char* what) {
  if (PyBool_Check(v.ptr())) return v.ptr() == Py_True ? 1 : 0;
  return static_cast<std::uint8_t>(int_in_range(v, what, 0, 1));
}

}  // namespace

PyObject* sanitizer_warning() {
  static PyObject* w = PyErr_NewExceptionWithDoc(
      "l6470emu._l6470emu.SanitizerWarning",
      "A broken rule of the chip's interface under check=\"warn\" (the sanitizer's report line).", PyExc_UserWarning,
      nullptr);
  return w;
}

void warn_sanitizer_lines(const std::vector<std::string>& lines) {
  for (const std::string& line : lines)
    if (PyErr_WarnEx(sanitizer_warning(), line.c_str(), 1) != 0) throw py::error_already_set();
}

void bind_chain(py::module_& m) {
  static py::exception<SanitizerFailure> error = py::register_exception<SanitizerFailure>(m, "SanitizerError", PyExc_AssertionError);
  error.attr("__doc__") = "A broken rule of the chip's interface under check=\"error\": the sanitizer's report.";
  m.attr("SanitizerWarning") = py::handle(sanitizer_warning());
  m.def(
      "check_rules",
      [] {
        std::vector<std::tuple<std::string, std::string, std::string>> out;
        for (const RuleInfo& r : rule_table()) out.emplace_back(r.name, r.about, r.datasheet);
        return out;
      },
      "The driver sanitizer's rules as (name, what it is about, where the datasheet states it).");
  m.attr("SANITIZER_EXIT_STATUS") = kSanitizerExitStatus;

  py::class_<ChainDiagnostic>(m, "Diagnostic", "A host mistake a chip noticed (it sets WRONG_CMD / NOTPERF_CMD as the chip would).")
      .def_readonly("tick", &ChainDiagnostic::tick, "when, in 250 ns ticks")
      .def_readonly("chip", &ChainDiagnostic::chip, "which chip")
      .def_readonly("kind", &ChainDiagnostic::kind, "\"wrong_cmd\", \"notperf_cmd\" or \"ignored\"")
      .def_readonly("message", &ChainDiagnostic::message, "what happened, in words")
      .def("__repr__", [](const ChainDiagnostic& d) {
        return "Diagnostic(chip " + std::to_string(d.chip) + ", " + d.kind + ": " + d.message + ")";
      });

  py::class_<PyChain> c(m, "Chain", R"(A daisy chain of emulated chips behind one chip-select, in virtual time.

Chip 0 drives MISO and is farthest from the host's MOSI: in a frame of N bytes, byte k is
for chip k and MISO byte k is chip k's answer. Nothing moves until time is advanced.

chips: variant names, chip 0 first ("L6470", "2xL6480", "3*L6470"), as a list or one
comma-separated string, or a number of L6470s. record: a path to record a native trace into (flushed frame by
frame), True to record into memory (Chain.trace), or None. check: the driver sanitizer,
"error" (default: the first broken rule of the chip, such as an unknown opcode, a refused
command, a frame that is not the chain's length or an answer never read, raises
l6470emu.SanitizerError with its report), "warn" (an l6470emu.SanitizerWarning each) or "off";
check_allow: rule names it lets pass (l6470emu.check_rules()). coverage: collect interface
coverage of everything the chain does and merge it into this file when the chain is closed,
destroyed, or the interpreter exits (docs/coverage-python.md); True collects it in memory only
(coverage_data()), False not at all; None (default) collects into $L6470EMU_COVERAGE when set.)");

  c.def(py::init([](py::object chips, py::object record, py::object frame_gap_ticks, py::object check, py::object check_allow,
                    py::object coverage) {
          const std::string spec = chain_spec_from(chips);
          std::vector<const Variant*> variants;
          try {
            variants = parse_chain_spec(spec);
          } catch (const std::invalid_argument& e) {
            throw py::value_error(std::string("chips: ") + e.what());
          }
          RecordTo to;
          if (PyBool_Check(record.ptr()))
            to.memory = record.ptr() == Py_True;
          else if (!record.is_none())
            to.path = path_from(record, "record");
          const auto gap = static_cast<Tick>(int_in_range(frame_gap_ticks, "frame_gap_ticks", 1, 1LL << 32));
          const CheckConfig cc = check_config_from(check, check_allow);
          const CoverageRequest cov = coverage_request_from(coverage);
          try {
            return std::make_unique<PyChain>(variants, to, gap, cc, cov);
          } catch (const std::runtime_error& e) {
            throw std::runtime_error(std::string("record: ") + e.what());
          }
        }),
        py::arg("chips") = "L6470", py::kw_only(), py::arg("record") = py::none(), py::arg("frame_gap_ticks") = 8,
        py::arg("check") = "error", py::arg("check_allow") = py::tuple(), py::arg("coverage") = py::none());
  c.def_property(
       "check", [](const PyChain& p) { return std::string(to_string(p.check().level)); },
       [](PyChain& p, py::object level) {
         CheckConfig cc = p.check();
         cc.level = check_config_from(level, py::tuple()).level;
         p.set_check(cc);
       },
       "The driver sanitizer's level: \"error\" (the default: the first broken rule of the chip raises "
       "SanitizerError with its report), \"warn\" (a SanitizerWarning each) or \"off\".")
      .def_property(
          "check_allow",
          [](const PyChain& p) {
            std::vector<std::string> out;
            for (const RuleInfo& r : rule_table())
              if (p.check().allowed.contains(r.rule)) out.emplace_back(r.name);
            return out;
          },
          [](PyChain& p, py::object rules) {
            CheckConfig cc = p.check();
            cc.allowed = check_config_from(py::str("error"), rules).allowed;
            p.set_check(cc);
          },
          "The rules the sanitizer lets pass (names as in l6470emu.check_rules()).");

  c.def("__len__", [](const PyChain& p) { return p.chain().size(); }, "Number of chips.")
      .def_property_readonly(
          "variants",
          [](const PyChain& p) {
            std::vector<std::string> out;
            for (std::size_t k = 0; k < p.chain().size(); ++k) out.emplace_back(p.chain().chip(k).variant().name);
            return out;
          },
          "The chips' variant names, chip 0 first.")
      .def_property_readonly("spec", [](const PyChain& p) { return chain_spec_of(p.chain()); },
                             "The chain as a description (\"2*L6470,L6480\"), as a trace's chain line.")
      .def("__repr__", [](const PyChain& p) {
        return "Chain(\"" + chain_spec_of(p.chain()) + "\", now=" + format_seconds(p.chain().now()) + " s)";
      });

  // ---- bytes ----------------------------------------------------------------
  c.def(
       "frame",
       [](PyChain& p, py::handle data, py::object out) -> py::object {
         const std::vector<std::uint8_t> tx = bytes_from(data, "frame data");
         std::vector<std::uint8_t> rx(tx.size());
         if (!out.is_none()) {
           // Check the output buffer before anything reaches the chain.
           bytes_into(out, rx, "out");
           p.frame(tx, rx);
           bytes_into(out, rx, "out");
           after_spi(p);
           return out;
         }
         p.frame(tx, rx);
         after_spi(p);
         return py::bytes(reinterpret_cast<const char*>(rx.data()), rx.size());
       },
       py::arg("data"), py::arg("out") = py::none(),
       R"(One CS frame: CS falls, every byte of data is clocked through the chain, CS rises.

data: bytes, bytearray, memoryview, a numpy uint8 array or a list of ints. Returns the MISO
bytes, or writes them into out (a writable buffer of the same length) and returns out.
Time does not advance by itself: call advance() between frames as a bus would take time.)")
      .def(
          "send",
          [](PyChain& p, py::handle chip, py::handle data) {
            const std::size_t k = chip_arg(p, chip);
            const auto tx = bytes_from(data, "data");
            const auto rx = p.host().send(k, tx);
            after_spi(p);
            return py::bytes(reinterpret_cast<const char*>(rx.data()), rx.size());
          },
          py::arg("chip"), py::arg("data"),
          "Sends bytes to one chip, one frame per byte (NOP to the others); returns that chip's MISO byte of each frame.")
      .def("nop", [](PyChain& p, py::handle chip) { p.host().nop(chip_arg(p, chip)); after_spi(p); }, py::arg("chip"),
           "A NOP frame for the chip.");

  // ---- the reference host's commands -------------------------------------------
  c.def(
       "get_status",
       [](PyChain& p, py::handle chip) {
         const std::size_t k = chip_arg(p, chip);
         const std::uint16_t s = p.host().get_status(k);
         after_spi(p);
         return make_status(p.chain().chip(k), s);
       },
       py::arg("chip"), "GetStatus: the STATUS answer (an int with its flags decoded); clears the latched flags.")
      .def(
          "get_param",
          [](PyChain& p, py::handle chip, py::handle reg) {
            const std::size_t k = chip_arg(p, chip);
            const std::uint32_t v = p.host().get_param(k, register_from(p.chain().chip(k), k, reg).id);
            after_spi(p);
            return v;
          },
          py::arg("chip"), py::arg("reg"),
          "GetParam: the register's value as the chip answers it (raw bits; ABS_POS/MARK unsigned 22-bit). "
          "reg: an l6470emu.Reg, a name or an address.")
      .def(
          "set_param",
          [](PyChain& p, py::handle chip, py::handle reg, py::handle value) {
            const std::size_t k = chip_arg(p, chip);
            const RegisterInfo& r = register_from(p.chain().chip(k), k, reg);
            const long long max = (1LL << (8 * r.spi_bytes())) - 1;
            long long v = int_in_range(value, (std::string("value of ") + std::string(r.name)).c_str(),
                                       r.is_signed() ? -(1LL << (r.bits - 1)) : 0, max);
            if (v < 0) v &= (1LL << r.bits) - 1;
            p.host().set_param(k, r.id, static_cast<std::uint32_t>(v));
            after_spi(p);
          },
          py::arg("chip"), py::arg("reg"), py::arg("value"),
          "SetParam: value in the register's SPI bytes (bits above its width are ignored by the chip, as on "
          "hardware; ABS_POS and MARK also take negative numbers). Refusals set NOTPERF_CMD as the chip does.")
      .def(
          "run",
          [](PyChain& p, py::handle chip, bool forward, py::handle speed) {
            p.host().run(chip_arg(p, chip), forward, static_cast<std::uint32_t>(int_in_range(speed, "speed", 0, kMax20)));
            after_spi(p);
          },
          py::arg("chip"), py::arg("forward"), py::arg("speed"), "Run at speed (SPEED units, 2^-28 step/tick).")
      .def("step_clock", [](PyChain& p, py::handle chip, bool forward) { p.host().step_clock(chip_arg(p, chip), forward); after_spi(p); },
           py::arg("chip"), py::arg("forward"), "StepClock: step-clock mode (STCK rising edges make microsteps).")
      .def(
          "move",
          [](PyChain& p, py::handle chip, bool forward, py::handle n_step) {
            p.host().move(chip_arg(p, chip), forward, static_cast<std::uint32_t>(int_in_range(n_step, "n_step", 0, kMax22)));
            after_spi(p);
          },
          py::arg("chip"), py::arg("forward"), py::arg("n_step"), "Move n_step microsteps (0..2^22-1).")
      .def(
          "go_to",
          [](PyChain& p, py::handle chip, py::handle abs_pos) { p.host().go_to(chip_arg(p, chip), position_arg(abs_pos, "abs_pos")); after_spi(p); },
          py::arg("chip"), py::arg("abs_pos"), "GoTo abs_pos the shortest way (22-bit position; negative allowed).")
      .def(
          "goto",
          [](PyChain& p, py::handle chip, py::handle abs_pos) { p.host().go_to(chip_arg(p, chip), position_arg(abs_pos, "abs_pos")); after_spi(p); },
          py::arg("chip"), py::arg("abs_pos"), "Same as go_to().")
      .def(
          "go_to_dir",
          [](PyChain& p, py::handle chip, bool forward, py::handle abs_pos) {
            p.host().go_to_dir(chip_arg(p, chip), forward, position_arg(abs_pos, "abs_pos"));
            after_spi(p);
          },
          py::arg("chip"), py::arg("forward"), py::arg("abs_pos"), "GoTo_DIR: to abs_pos in the given direction.")
      .def(
          "go_until",
          [](PyChain& p, py::handle chip, bool copy_to_mark, bool forward, py::handle speed) {
            p.host().go_until(chip_arg(p, chip), copy_to_mark, forward,
                              static_cast<std::uint32_t>(int_in_range(speed, "speed", 0, kMax20)));
            after_spi(p);
          },
          py::arg("chip"), py::arg("copy_to_mark"), py::arg("forward"), py::arg("speed"),
          "GoUntil: run at speed until SW closes; copy_to_mark (ACT) copies ABS_POS to MARK instead of resetting it.")
      .def(
          "release_sw",
          [](PyChain& p, py::handle chip, bool copy_to_mark, bool forward) {
            p.host().release_sw(chip_arg(p, chip), copy_to_mark, forward);
            after_spi(p);
          },
          py::arg("chip"), py::arg("copy_to_mark"), py::arg("forward"), "ReleaseSW: at minimum speed until SW opens.");

  const std::pair<const char*, void (ChainHost::*)(std::size_t)> simple[] = {
      {"go_home", &ChainHost::go_home},         {"go_mark", &ChainHost::go_mark},     {"reset_pos", &ChainHost::reset_pos},
      {"reset_device", &ChainHost::reset_device}, {"soft_stop", &ChainHost::soft_stop}, {"hard_stop", &ChainHost::hard_stop},
      {"soft_hiz", &ChainHost::soft_hiz},       {"hard_hiz", &ChainHost::hard_hiz},
      {"enable", &ChainHost::enable},           {"disable", &ChainHost::disable},
  };
  const char* simple_docs[] = {"GoHome: to position 0.", "GoMark: to MARK.", "ResetPos: ABS_POS = 0.",
                               "ResetDevice: registers to their reset values.", "SoftStop: decelerate to a stop.",
                               "HardStop: stop at once.", "SoftHiZ: decelerate, then bridges off.",
                               "HardHiZ: bridges off at once.",
                               "Enable, an L6474's command (HardStop's opcode 0xB8): bridges on.",
                               "Disable, an L6474's command (HardHiZ's opcode 0xA8): bridges off at once."};
  for (std::size_t i = 0; i < std::size(simple); ++i) {
    const auto fn = simple[i].second;
    c.def(simple[i].first, [fn](PyChain& p, py::handle chip) { (p.host().*fn)(chip_arg(p, chip)); after_spi(p); }, py::arg("chip"),
          simple_docs[i]);
  }

  // ---- looking without side effects --------------------------------------------
  c.def(
       "status",
       [](PyChain& p, py::handle chip) {
         const Chip& ch = p.chain().chip(chip_arg(p, chip));
         return make_status(ch, ch.status());
       },
       py::arg("chip"), "STATUS as GetParam(STATUS) reads it now, without clearing anything (no SPI traffic).")
      .def(
          "peek",
          [](PyChain& p, py::handle chip, py::handle reg) {
            const std::size_t k = chip_arg(p, chip);
            const Chip& ch = p.chain().chip(k);
            return ch.peek(register_from(ch, k, reg).id);
          },
          py::arg("chip"), py::arg("reg"), "The value GetParam would return now, without SPI traffic.")
      .def("position", [](PyChain& p, py::handle chip) { return p.chain().chip(chip_arg(p, chip)).position(); },
           py::arg("chip"), "ABS_POS as a signed number of microsteps (no SPI traffic).")
      .def("dump", [](PyChain& p, py::handle chip) { return p.chain().chip(chip_arg(p, chip)).dump(); }, py::arg("chip"),
           "Every register of the chip as text, STATUS decoded.")
      .def("variant", [](PyChain& p, py::handle chip) { return std::string(p.chain().chip(chip_arg(p, chip)).variant().name); },
           py::arg("chip"), "The chip's variant name.")
      .def(
          "registers",
          [](PyChain& p, py::handle chip) {
            const Variant& t = p.chain().chip(chip_arg(p, chip)).registers();
            return std::vector<RegisterInfo>(t.registers.begin(), t.registers.end());
          },
          py::arg("chip"), "The chip's register table in force (a powerSTEP01 in current mode shows TVAL_*...).");

  // ---- time ----------------------------------------------------------------------
  c.def_property_readonly("now", [](const PyChain& p) { return p.chain().now(); },
                          "Virtual time in 250 ns ticks since power-up.")
      .def_property_readonly("now_seconds", [](const PyChain& p) { return static_cast<double>(p.chain().now()) / kTicksPerSecond; },
                             "Virtual time in seconds.")
      .def(
          "advance",
          [](PyChain& p, py::object seconds, py::object ticks) {
            if (seconds.is_none() == ticks.is_none())
              throw py::value_error("advance() takes seconds=... or ticks=..., exactly one of them");
            Tick dt = 0;
            if (!ticks.is_none()) {
              dt = static_cast<Tick>(int_in_range(ticks, "ticks", 0, 1LL << 62));
            } else {
              const double s = py::float_(seconds);
              if (!std::isfinite(s) || s < 0 || s > 1e12)
                throw py::value_error("seconds = " + std::string(py::str(seconds)) + " is not a time from 0 to 1e12 s");
              dt = static_cast<Tick>(std::llround(s * static_cast<double>(kTicksPerSecond)));
            }
            p.advance_to(p.chain().now() + dt);
          },
          py::kw_only(), py::arg("seconds") = py::none(), py::arg("ticks") = py::none(),
          "Lets virtual time pass: seconds (rounded to the 250 ns tick) or ticks.")
      .def(
          "advance_to",
          [](PyChain& p, py::handle tick) {
            const auto t = static_cast<Tick>(int_in_range(tick, "tick", 0, 1LL << 62));
            if (t < p.chain().now())
              throw py::value_error("tick " + std::to_string(t) + " is in the past (now is " + std::to_string(p.chain().now()) + ")");
            p.advance_to(t);
          },
          py::arg("tick"), "Lets virtual time run up to tick (never backwards).")
      .def(
          "next_event",
          [](const PyChain& p) -> py::object {
            const Tick t = p.chain().next_event_tick();
            if (t == kNever) return py::none();
            return py::int_(t);
          },
          "The tick at which some chip changes on its own next (a profile phase, a move's end), or None when all are idle.");

  // ---- the physical world ------------------------------------------------------------
  c.def("attach_axis", [](PyChain& p, py::handle chip, const std::string& spec) {
        const std::size_t k = chip_arg(p, chip);
        p.attach_axis(k, axis_from_text(p.chain().chip(k), spec == "default" ? std::string() : spec));
      }, py::arg("chip"), py::arg("spec") = "default",
      "Puts a motor, load, stops and switches behind chip `chip` (the board description's axis items:\n"
      "\"steps=200,load=120,stops=-2000..90000,switch=home@0\"; positions in 1/128 step). An axis already\n"
      "attached keeps its items and its rotor position; the items given change it. From then on the\n"
      "axis drives SW, the stall and the overcurrent conditions.");
  c.def("axis", [](PyChain& p, py::handle chip) { return axis_state(p.chain().chip(chip_arg(p, chip))); },
        py::arg("chip"),
        "The axis now: position (true, 1/128 step), lost_steps, synchronised, at_stop, switches\n"
        "(name: actuated), sw_level, stall, overcurrent, phase_current_mA, spec.");
  c.def("set_load", [](PyChain& p, py::handle chip, const std::string& load) {
        const std::size_t k = chip_arg(p, chip);
        p.set_axis_load(k, load_from_text(p.chain().chip(k), load));
      }, py::arg("chip"), py::arg("load"), "Changes the axis's load now: \"load=G_CM2,friction=NM,force=NM\".");
  c.def("set_sw_pin", [](PyChain& p, py::handle chip, py::handle level) { p.set_sw_pin(chip_arg(p, chip), level_arg(level, "level")); },
        py::arg("chip"), py::arg("level"), "SW input level: False/0 = switch closed (pulled to ground).")
      .def("sw_pin", [](PyChain& p, py::handle chip) { return p.chain().chip(chip_arg(p, chip)).sw_pin(); }, py::arg("chip"),
           "SW input level.")
      .def("set_stck_pin", [](PyChain& p, py::handle chip, py::handle level) { p.set_stck_pin(chip_arg(p, chip), level_arg(level, "level")); },
           py::arg("chip"), py::arg("level"),
           "STCK input level; a rising edge in step-clock mode makes one microstep (an L6474: each rising edge while "
           "its bridges are enabled, in the direction of its DIR pin).")
      .def("set_dir_pin", [](PyChain& p, py::handle chip, py::handle level) { p.set_dir_pin(chip_arg(p, chip), level_arg(level, "level")); },
           py::arg("chip"), py::arg("level"),
           "DIR input level of an L6474 (the direction STCK steps in: True/1 = forward); other parts have no DIR pin "
           "and ignore it.")
      .def("dir_pin", [](PyChain& p, py::handle chip) { return p.chain().chip(chip_arg(p, chip)).dir_pin(); }, py::arg("chip"),
           "DIR input level.")
      .def("set_stby_rst_pin",
           [](PyChain& p, py::handle chip, py::handle level) { p.set_stby_rst_pin(chip_arg(p, chip), level_arg(level, "level")); },
           py::arg("chip"), py::arg("level"), "STBY/RST input: low holds the logic in reset (SPI silent); rising edge = power-up state.")
      .def("busy_pin",
           [](PyChain& p, py::handle chip) {
             const std::size_t k = chip_arg(p, chip);
             const bool level = p.chain().chip(k).busy_sync_pin();
             p.note_output_read(k, Pin::BUSY, level);  // the host's read (coverage: BUSY observed, an edge waited on)
             return level;
           },
           py::arg("chip"), "BUSY/SYNC output level: False = pulled low (busy). A read by the host, for coverage.")
      .def("flag_pin",
           [](PyChain& p, py::handle chip) {
             const std::size_t k = chip_arg(p, chip);
             const bool level = p.chain().chip(k).flag_pin();
             p.note_output_read(k, Pin::FLAG, level);
             return level;
           },
           py::arg("chip"), "FLAG output level: False = pulled low (an enabled alarm is active). A read by the host, for coverage.")
      .def("set_adc_input",
           [](PyChain& p, py::handle chip, py::handle code) {
             p.set_adc_input(chip_arg(p, chip), static_cast<std::uint8_t>(int_in_range(code, "code", 0, 31)));
           },
           py::arg("chip"), py::arg("code"), "The ADCIN pin as the ADC_OUT code it converts to (0..31).")
      .def("set_undervoltage",
           [](PyChain& p, py::handle chip, bool active) { p.fault(chip_arg(p, chip), TraceFault::UVLO, active); },
           py::arg("chip"), py::arg("active"), "Motor supply below VSthOff (True) or back above VSthOn (False).")
      .def("set_adc_undervoltage",
           [](PyChain& p, py::handle chip, bool active) { p.fault(chip_arg(p, chip), TraceFault::UVLO_ADC, active); },
           py::arg("chip"), py::arg("active"), "ADC input undervoltage (UVLO_ADC, gate-driver parts).")
      .def("set_thermal",
           [](PyChain& p, py::handle chip, py::handle level) {
             p.fault(chip_arg(p, chip), TraceFault::THERMAL, static_cast<std::uint8_t>(thermal_from(level)));
           },
           py::arg("chip"), py::arg("level"), "Die temperature class: an l6470emu.Thermal or its name (\"warning\").")
      .def("set_overcurrent",
           [](PyChain& p, py::handle chip, bool active) { p.fault(chip_arg(p, chip), TraceFault::OCD, active); },
           py::arg("chip"), py::arg("active"), "Overcurrent in a power MOSFET (with CONFIG.OC_SD the bridges shut down).")
      .def("set_stall",
           [](PyChain& p, py::handle chip, py::handle bridge, bool active) {
             p.fault(chip_arg(p, chip), bridge_from(bridge) == Bridge::A ? TraceFault::STALL_A : TraceFault::STALL_B, active);
           },
           py::arg("chip"), py::arg("bridge"), py::arg("active"), "Stall (step loss) on bridge \"A\" or \"B\".")
      .def("fault",
           [](PyChain& p, py::handle chip, py::handle fault, py::handle value) {
             const std::size_t k = chip_arg(p, chip);
             const TraceFault f = fault_from(fault);
             std::uint8_t v = 0;
             if (f == TraceFault::POWER_CYCLE || f == TraceFault::LOST_FRAME)
               v = 0;  // one-shot: no value
             else if (f == TraceFault::MISO_FLIP)
               v = value.is_none() ? 7 : static_cast<std::uint8_t>(int_in_range(value, "value", 0, 7));
             else if (value.is_none())
               v = 1;
             else if (f == TraceFault::THERMAL)
               v = static_cast<std::uint8_t>(thermal_from(value));
             else if (f == TraceFault::ADCIN)
               v = static_cast<std::uint8_t>(int_in_range(value, "value", 0, 31));
             else
               v = level_arg(value, "value");
             p.fault(k, f, v);
           },
           py::arg("chip"), py::arg("fault"), py::arg("value") = py::none(),
           "A backdoor event as a trace writes it: fault UVLO/UVLO_ADC/OCD/STALL_A/STALL_B with value True/False "
           "(default True), THERMAL with a Thermal, ADCIN with a code 0..31; the one-shot POWER_CYCLE (a brown-out) "
           "and LOST_FRAME (the chip misses the next frame) take no value, MISO_FLIP the bit 0..7 (default 7) "
           "inverted in the chip's MISO byte of the next frame.");

  // ---- recording and diagnostics --------------------------------------------------------
  c.def_property_readonly("recording", &PyChain::recording, "Whether frames, pins and faults are being recorded.")
      .def_property_readonly(
          "record_path", [](const PyChain& p) -> py::object {
            if (p.record_path().empty()) return py::none();
            return py::str(p.record_path());
          },
          "The native trace file recorded into, or None.")
      .def_property_readonly(
          "trace",
          [](const PyChain& p) -> py::object {
            if (const Trace* t = p.memory_trace()) return py::cast(*t);
            return py::none();
          },
          "A copy of the trace recorded in memory (Chain(..., record=True)), else None.")
      .def("close", &close_chain,
           "Stops recording (a trace file is complete and closed) and merges the interface coverage met so far "
           "into the coverage file (RuntimeError when it cannot be written); the chain stays usable.")
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](PyChain& p, py::args) { close_chain(p); })
      .def(
          "take_diagnostics",
          [](PyChain& p) {
            std::uint64_t dropped = 0;
            auto out = p.take_diagnostics(dropped);
            return out;
          },
          "The host mistakes the chips noticed since the last call (unknown opcodes, refused commands), oldest first.");

  // ---- interface coverage ---------------------------------------------------------------
  c.def("coverage_data",
        [](const PyChain& p) -> py::object { return p.collecting_coverage() ? coverage_dict(p.coverage()) : py::none(); },
        "The interface coverage met so far as a dict, the coverage file's structure ({\"format\", \"version\", "
        "\"variants\": {VARIANT: {\"hit\": {CATEGORY: [POINT, ...]}, \"chain positions present\": [...]}}}), "
        "or None when the chain collects none.")
      .def_property_readonly(
          "coverage_path",
          [](const PyChain& p) -> py::object {
            if (p.coverage_path().empty()) return py::none();
            return py::str(p.coverage_path());
          },
          "The coverage file the chain merges into (absolute), or None.");
}

}  // namespace l6470emu::python
