// l6470emu._BoardCore: the board of a board description in virtual time, in the test process,
// for l6470emu.Board (board.py), which gives it spidev.SpiDev-like devices and libgpiod-like
// lines. Also the axis behind a chip (attach, read, change the load), shared with Chain.
#include <pybind11/stl.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "core/axis_text.hpp"
#include "board/board_config.hpp"
#include "bindings.hpp"
#include "convert.hpp"
#include "py_board.hpp"
#include "sanitizer_failure.hpp"

namespace l6470emu::python {
namespace {

[[noreturn]] void raise_errno(long neg_errno, const std::string& what) {
  const int e = static_cast<int>(-neg_errno);
  PyErr_SetObject(PyExc_OSError, py::make_tuple(e, std::string(std::strerror(e)) + " (" + what + ")").ptr());
  throw py::error_already_set();
}

std::size_t chain_arg(PyBoard& b, long long chain) {
  const auto n = static_cast<long long>(b.board().chain_count());
  if (chain < 0 || chain >= n)
    throw py::value_error("chain " + std::to_string(chain) + " is not on the board: it has " + std::to_string(n) +
                          (n == 1 ? " chain" : " chains"));
  return static_cast<std::size_t>(chain);
}

std::size_t chip_arg(PyBoard& b, std::size_t chain, long long chip) {
  const auto n = static_cast<long long>(b.board().chip_count(chain));
  if (chip < 0 || chip >= n)
    throw py::value_error("chip " + std::to_string(chip) + " is not in chain " + std::to_string(chain) + ": it has " +
                          std::to_string(n) + (n == 1 ? " chip (0)" : " chips (0.." + std::to_string(n - 1) + ")"));
  return static_cast<std::size_t>(chip);
}

Pin pin_arg(long long pin) {
  if (pin < 0 || pin >= static_cast<long long>(kPinsPerChip))
    throw py::value_error("pin " + std::to_string(pin) + ": 0..5 (BUSY, FLAG, SW, STCK, STBY_RST, DIR)");
  return static_cast<Pin>(pin);
}

Tick tick_arg(long long t) {
  if (t < 0) throw py::value_error("tick " + std::to_string(t) + " is negative");
  return static_cast<Tick>(t);
}

}  // namespace

py::dict axis_state(const Chip& chip) {
  const Axis* a = chip.axis();
  if (!a) throw py::value_error("no axis is attached to this chip (attach_axis first)");
  py::dict d;
  d["position"] = a->true_position();
  d["lost_steps"] = a->lost_steps();
  d["synchronised"] = a->synchronised();
  d["at_stop"] = a->at_stop();
  d["sw_level"] = a->sw_level();
  d["stall"] = a->stall_condition();
  d["overcurrent"] = a->overcurrent_condition();
  d["phase_current_mA"] = a->phase_current_mA();
  py::dict sw;
  for (std::size_t i = 0; i < a->spec().switches.size(); ++i) sw[py::str(a->spec().switches[i].name)] = a->switch_actuated(i);
  d["switches"] = sw;
  d["spec"] = describe_axis_spec(a->spec());
  return d;
}

AxisSpec axis_from_text(const Chip& chip, const std::string& text) {
  AxisSpec spec;
  if (const Axis* a = chip.axis()) {  // items given change the axis attached; the rotor stays where it is
    spec = a->spec();
    spec.start_position = a->true_position();
  }
  if (std::string err = parse_axis_spec(text, spec); !err.empty()) throw py::value_error("axis: " + err);
  return spec;
}

LoadSpec load_from_text(const Chip& chip, const std::string& text) {
  const Axis* a = chip.axis();
  if (!a) throw py::value_error("no axis is attached to this chip (attach_axis first)");
  LoadSpec load = a->spec().load;
  if (std::string err = parse_axis_load(text, load); !err.empty()) throw py::value_error("load: " + err);
  return load;
}

void bind_board(py::module_& m) {
  py::class_<PyBoard> b(m, "_BoardCore", "The board behind l6470emu.Board (use that class).");
  b.def(py::init([](const std::string& description, const std::string& origin, py::object coverage) {
          ParseResult r = parse_board_config(description, origin);
          if (!r.config) throw py::value_error(r.error.message);
          if (!r.config->time.virtual_time)
            throw py::value_error("l6470emu: " + origin +
                                  ": a board in the test process runs in virtual time (drop time=wall; "
                                  "spidev_board runs programs in wall time)");
          return std::make_unique<PyBoard>(*r.config, coverage_request_from(coverage));
        }),
        py::arg("description"), py::arg("origin"), py::arg("coverage") = py::none());
  b.def("chain_count", [](PyBoard& s) { return s.board().chain_count(); });
  b.def("chip_count", [](PyBoard& s, long long c) { return s.board().chip_count(chain_arg(s, c)); });
  b.def("chain_name", [](PyBoard& s, long long c) { return s.board().chain_name(chain_arg(s, c)); });
  b.def("chain_summary", [](PyBoard& s, long long c) { return s.board().chain_summary(chain_arg(s, c)); });
  b.def("find_chain", [](PyBoard& s, const std::string& name) { return s.board().find_chain(name); });
  b.def("bus_cs", [](PyBoard& s, long long c) {
    const ChainConfig& cc = s.board().chain_config(chain_arg(s, c));
    return py::make_tuple(cc.bus, cc.cs);
  });
  b.def("variants", [](PyBoard& s, long long c) {
    const Chain& ch = s.board().chain(chain_arg(s, c));
    std::vector<std::string> out;
    for (std::size_t k = 0; k < ch.size(); ++k) out.emplace_back(ch.chip(k).variant().name);
    return out;
  });
  b.def("has_pin", [](PyBoard& s, long long c, long long k, long long p) {
    const std::size_t chain = chain_arg(s, c);
    return variant_has_pin(s.board().chain(chain).chip(chip_arg(s, chain, k)).variant(), pin_arg(p));
  });
  b.def("gpiochip", [](PyBoard& s, long long c) -> py::object {
    const ChainConfig& cc = s.board().chain_config(chain_arg(s, c));
    return cc.gpiochip ? py::int_(*cc.gpiochip) : py::object(py::none());
  });

  // spidev
  b.def("spi_open", [](PyBoard& s, long long c) { s.open(chain_arg(s, c)); });
  b.def("spi_close", [](PyBoard& s, long long c) { s.close(chain_arg(s, c)); });
  b.def("spi_settings", [](PyBoard& s, long long c) {
    const SpidevSettings& st = s.spi(chain_arg(s, c));
    return py::make_tuple(st.mode, st.bits_per_word, st.speed_hz, st.bufsiz);
  });
  b.def("spi_ioctl", [](PyBoard& s, long long c, const std::string& what, std::uint32_t value) {
    // The settings ioctls py-spidev issues, with the kernel's checks (spidev_rules).
    SpidevSettings& st = s.spi(chain_arg(s, c));
    unsigned long cmd = 0;
    if (what == "mode32") cmd = SPI_IOC_WR_MODE32;
    else if (what == "bits_per_word") cmd = SPI_IOC_WR_BITS_PER_WORD;
    else if (what == "max_speed_hz") cmd = SPI_IOC_WR_MAX_SPEED_HZ;
    else throw py::value_error("spi_ioctl: " + what);
    const long r = spidev_settings_ioctl(st, cmd, value);
    if (r < 0) raise_errno(r, what + " " + std::to_string(value));
  });
  b.def("spi_message", [](PyBoard& s, long long c, const py::list& transfers) {
    // Each transfer: (tx bytes or None, rx wanted, len, speed_hz, delay_usecs, bits_per_word,
    // cs_change, word_delay_usecs), as struct spi_ioc_transfer.
    const std::size_t chain = chain_arg(s, c);
    std::vector<spi_ioc_transfer> xfers;
    std::vector<std::uint8_t> tx;
    std::size_t rx_len = 0;
    for (py::handle t : transfers) {
      auto tup = t.cast<py::tuple>();
      if (tup.size() != 8) throw py::value_error("spi_message: a transfer is 8 fields");
      spi_ioc_transfer x{};
      x.len = static_cast<std::uint32_t>(int_in_range(tup[2], "len", 0, 0xFFFFFFFFLL));
      if (!tup[0].is_none()) {
        std::vector<std::uint8_t> data = bytes_from(tup[0], "tx");
        if (data.size() != x.len) throw py::value_error("spi_message: tx is not len bytes");
        tx.insert(tx.end(), data.begin(), data.end());
        x.tx_buf = 1;
      }
      if (tup[1].cast<bool>()) {
        x.rx_buf = 1;
        rx_len += x.len;
      }
      x.speed_hz = static_cast<std::uint32_t>(int_in_range(tup[3], "speed_hz", 0, 0xFFFFFFFFLL));
      x.delay_usecs = static_cast<std::uint16_t>(int_in_range(tup[4], "delay_usecs", 0, 0xFFFF));
      x.bits_per_word = static_cast<std::uint8_t>(int_in_range(tup[5], "bits_per_word", 0, 0xFF));
      x.cs_change = tup[6].cast<bool>() ? 1 : 0;
      x.word_delay_usecs = static_cast<std::uint8_t>(int_in_range(tup[7], "word_delay_usecs", 0, 0xFF));
      xfers.push_back(x);
    }
    std::vector<std::uint8_t> rx(rx_len);
    const long r = s.message(chain, xfers, tx, rx);
    warn_sanitizer_lines(s.take_check_lines());  // check=warn, as a Chain does
    if (r < 0) raise_errno(r, "SPI_IOC_MESSAGE");
    return py::bytes(reinterpret_cast<const char*>(rx.data()), rx.size());
  });

  // time
  b.def("now", [](PyBoard& s) { return s.board().time().now(); });
  b.def("advance_to", [](PyBoard& s, long long t) { s.board().advance_to(tick_arg(t)); });
  b.def("next_edge_tick", [](PyBoard& s) -> py::object {
    const Tick t = s.board().next_edge_tick();
    return t == kNever ? py::object(py::none()) : py::object(py::int_(t));
  });

  // pins
  b.def("level", [](PyBoard& s, long long c, long long k, long long p) {
    const std::size_t chain = chain_arg(s, c);
    return s.board().pin_level(chain, chip_arg(s, chain, k), pin_arg(p));
  });
  b.def("drive", [](PyBoard& s, long long c, long long k, long long p, bool level) {
    const std::size_t chain = chain_arg(s, c);
    const std::size_t chip = chip_arg(s, chain, k);
    if (s.board().drive_pin(chain, chip, pin_arg(p), level)) return;
    if (pin_is_chip_output(pin_arg(p)))
      throw py::value_error(std::string(pin_name(pin_arg(p))) + " is the chip's output: it cannot be driven");
    const std::string variant(s.board().chain(chain).chip(chip).variant().name);
    throw py::value_error("chip " + std::to_string(k) + " is an " + variant + ", which has no " + pin_name(pin_arg(p)) + " pin");
  });
  b.def("watch", [](PyBoard& s, long long c, long long k, long long p, bool on) {
    const std::size_t chain = chain_arg(s, c);
    s.watch(chain, chip_arg(s, chain, k), pin_arg(p), on);
  });
  b.def("take_edges", [](PyBoard& s, long long c, long long k, long long p) {
    const std::size_t chain = chain_arg(s, c);
    std::uint64_t dropped = 0;
    auto edges = s.take_edges(chain, chip_arg(s, chain, k), pin_arg(p), dropped);
    return py::make_tuple(edges, dropped);
  });
  b.def("wait_edge", [](PyBoard& s, long long c, long long k, long long p, long long deadline) {
    const std::size_t chain = chain_arg(s, c);
    return s.wait_edge(chain, chip_arg(s, chain, k), pin_arg(p), tick_arg(deadline));
  });

  // the backdoor, the axis, recording, the log
  b.def("fault", [](PyBoard& s, long long c, long long k, py::handle fault, long long value) {
    const std::size_t chain = chain_arg(s, c);
    const TraceFault f = fault_from(fault);
    // value -1: the default (on; bit 7 for MISO_FLIP); POWER_CYCLE and LOST_FRAME take none.
    if (value < 0) value = f == TraceFault::MISO_FLIP ? 7 : f == TraceFault::POWER_CYCLE || f == TraceFault::LOST_FRAME ? 0 : 1;
    if (f == TraceFault::POWER_CYCLE || f == TraceFault::LOST_FRAME) value = 0;
    const long long hi = f == TraceFault::THERMAL ? 3 : f == TraceFault::ADCIN ? 31 : f == TraceFault::MISO_FLIP ? 7 : 1;
    if (value < 0 || value > hi) throw py::value_error("fault value " + std::to_string(value) + ": 0.." + std::to_string(hi));
    s.board().inject_fault(chain, chip_arg(s, chain, k), f, static_cast<std::uint8_t>(value));
  });
  b.def("attach_axis", [](PyBoard& s, long long c, long long k, const std::string& text) {
    const std::size_t chain = chain_arg(s, c);
    const std::size_t chip = chip_arg(s, chain, k);
    AxisSpec spec;
    s.board().with_chain(chain, [&](Chain& ch) { spec = axis_from_text(ch.chip(chip), text); });
    s.board().attach_axis(chain, chip, spec);  // an axis event in the board's recordings
  });
  b.def("set_load", [](PyBoard& s, long long c, long long k, const std::string& text) {
    const std::size_t chain = chain_arg(s, c);
    const std::size_t chip = chip_arg(s, chain, k);
    LoadSpec load;
    s.board().with_chain(chain, [&](Chain& ch) { load = load_from_text(ch.chip(chip), text); });
    s.board().set_axis_load(chain, chip, load);  // a load event in the board's recordings
  });
  b.def("axis", [](PyBoard& s, long long c, long long k) {
    const std::size_t chain = chain_arg(s, c);
    const std::size_t chip = chip_arg(s, chain, k);
    s.board().catch_up(chain);
    return axis_state(s.board().chain(chain).chip(chip));
  });
  b.def("start_recording", [](PyBoard& s, long long c, py::handle path) {
    const std::string err = s.board().start_recording(chain_arg(s, c), path_from(path, "path"));
    if (!err.empty()) throw py::value_error(err);
  });
  b.def("start_recording_all", [](PyBoard& s, py::handle path) {
    const std::string err = s.board().start_recording_all(path_from(path, "path"));
    if (!err.empty()) throw py::value_error(err);
  });
  b.def("stop_recording", [](PyBoard& s, long long c) { return s.board().stop_recording(chain_arg(s, c)); });
  // what the host (the code under test) reads, and interface coverage
  b.def("note_output_read", [](PyBoard& s, long long c, long long k, long long p) {
    const std::size_t chain = chain_arg(s, c);
    s.board().note_output_read(chain, chip_arg(s, chain, k), pin_arg(p));
  });
  b.def("note_output_edge", [](PyBoard& s, long long c, long long k, long long p, bool rising) {
    const std::size_t chain = chain_arg(s, c);
    s.board().note_output_edge(chain, chip_arg(s, chain, k), pin_arg(p), rising);
  });
  b.def("coverage_data", [](PyBoard& s) -> py::object {
    return s.board().coverage_enabled() ? coverage_dict(s.board().coverage()) : py::none();
  });
  b.def("coverage_path", [](PyBoard& s) -> py::object {
    return s.coverage_path().empty() ? py::object(py::none()) : py::object(py::str(s.coverage_path()));
  });
  b.def("flush_coverage", [](PyBoard& s) {
    if (const std::string why = s.flush_coverage(); !why.empty())
      throw std::runtime_error("l6470emu: coverage not written: " + why);
  });
  b.def("take_log", [](PyBoard& s) {
    std::uint64_t dropped = 0;
    auto lines = s.take_log(dropped);
    return py::make_tuple(lines, dropped);
  });
}

}  // namespace l6470emu::python
