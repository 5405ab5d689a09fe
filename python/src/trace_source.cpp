#include "trace_source.hpp"

#include <limits>

#include "convert.hpp"
#include "daisychain/chain_spec.hpp"
#include "spi/trace_import.hpp"

namespace l6470emu::python {

TraceFormat format_arg(const py::object& format) {
  if (format.is_none()) return TraceFormat::unknown;
  const std::string name = py::str(format);
  const TraceFormat f = trace_format_named(name);
  if (f == TraceFormat::unknown && name != "auto")
    throw py::value_error("format: \"" + name + "\" is not native, saleae, umockdev, ftrace, sigrok or vcd");
  return f;
}

std::uint64_t max_frames_arg(py::handle max_frames) {
  return static_cast<std::uint64_t>(int_in_range(max_frames, "max_frames", 0, std::numeric_limits<long long>::max()));
}

Source source_of(py::handle trace, py::handle chain, py::handle format, const std::string& select,
                 std::uint64_t max_frames) {
  Source s;
  std::string spec;
  if (!chain.is_none()) spec = chain_spec_from(chain);
  if (py::isinstance<Trace>(trace)) {
    s.trace = trace.cast<std::shared_ptr<Trace>>();
    const std::string& own = s.trace->header.chain;
    if (spec.empty() && own.empty())
      throw py::value_error("the trace names no chain: pass chain=... (e.g. chain=\"3*L6470\")");
    s.how = spec.empty() ? "from the trace" : "from chain=";
    try {
      s.variants = parse_chain_spec(spec.empty() ? own : spec);
    } catch (const std::invalid_argument& e) {
      throw py::value_error(std::string("chain: ") + e.what());
    }
    return s;
  }
  const std::string path = path_from(trace, "trace");
  if (!spec.empty()) {
    // Checked here so that the message names the argument (chain_for_trace names "--chain").
    try {
      parse_chain_spec(spec);
    } catch (const std::invalid_argument& e) {
      throw py::value_error(std::string("chain: ") + e.what());
    }
  }
  TraceInputOptions options;
  options.format = format_arg(py::reinterpret_borrow<py::object>(format));
  options.import.select = select;
  options.import.max_frames = max_frames;
  {
    py::gil_scoped_release unlocked;  // may read a large file or run sigrok-cli
    s.file = std::make_unique<TraceFile>(path, options);
    s.variants = chain_for_trace(spec, *s.file, s.how);
  }
  if (!spec.empty()) s.how = "from chain=";
  return s;
}

}  // namespace l6470emu::python
