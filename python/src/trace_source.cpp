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
                 std::uint64_t max_frames, py::handle board) {
  Source s;
  WorldOptions world;
  if (!chain.is_none()) world.chain = chain_spec_from(chain);
  if (!board.is_none()) world.board_file = path_from(board, "board");
  if (!world.chain.empty() && !world.board_file.empty())
    throw py::value_error("chain= and board= both describe the chain: give one of them");
  // A bad chain= is the argument's fault (ValueError naming it); a bad board file is TraceError.
  auto world_for = [&](const TraceHeader& header, const auto& guess) {
    try {
      return world_for_header(world, header, guess);
    } catch (const TraceError& e) {
      if (e.file() == "--chain") throw py::value_error(std::string("chain: ") + e.reason());
      throw;
    } catch (const std::invalid_argument& e) {
      throw py::value_error(e.what());
    }
  };
  if (py::isinstance<Trace>(trace)) {
    s.trace = trace.cast<std::shared_ptr<Trace>>();
    const std::function<std::vector<const Variant*>(std::string&)> no_guess = [](std::string&) -> std::vector<const Variant*> {
      throw std::invalid_argument("the trace names no chain: pass chain=... (e.g. chain=\"3*L6470\")");
    };
    s.world = world_for(s.trace->header, no_guess);
    if (!world.chain.empty() && world.chain.find('=') == std::string::npos) s.world.how = "from chain=";
    return s;
  }
  const std::string path = path_from(trace, "trace");
  TraceInputOptions options;
  options.format = format_arg(py::reinterpret_borrow<py::object>(format));
  options.import.select = select;
  options.import.max_frames = max_frames;
  {
    py::gil_scoped_release unlocked;  // may read a large file or run sigrok-cli
    s.file = std::make_unique<TraceFile>(path, options);
  }
  const TraceFile& file = *s.file;
  const std::function<std::vector<const Variant*>(std::string&)> guess = [&file](std::string& how) {
    py::gil_scoped_release unlocked;
    return chain_for_trace("", file, how);
  };
  s.world = world_for(file.header(), guess);
  if (!world.chain.empty() && world.chain.find('=') == std::string::npos) s.world.how = "from chain=";
  return s;
}

}  // namespace l6470emu::python
