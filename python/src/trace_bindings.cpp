// Traces for Python: l6470emu.Trace (a whole trace in memory: loaded from any format the
// l6470emu program reads, parsed from text, or recorded by a Chain), its events, and
// replay() / decode() over a Trace or a file (daisychain/replay.hpp, daisychain/decode.hpp).
#include <pybind11/stl.h>

#include <fstream>
#include <memory>
#include <sstream>

#include "bindings.hpp"
#include "core/counted.hpp"
#include "convert.hpp"
#include "trace_source.hpp"
#include "daisychain/chain_spec.hpp"
#include "daisychain/decode.hpp"
#include "daisychain/replay.hpp"
#include "spi/trace_file.hpp"
#include "spi/trace_import.hpp"
#include "spi/trace_native.hpp"
#include "tools/trace_input.hpp"

namespace l6470emu::python {
namespace {

/// One trace event with its bytes copied out (a TraceEvent's spans do not outlive the trace).
struct PyTraceEvent {
  std::string kind;
  Tick tick = 0;
  Tick duration = 0;
  py::bytes mosi;
  py::object miso;  // bytes, or None when the trace has no MISO for the frame
  std::vector<bool> miso_known;
  std::size_t chip = 0;
  py::object pin;    // str or None
  py::object fault;  // str or None
  unsigned value = 0;
  std::uint64_t line = 0;
  py::object source_time;  // float or None
  std::string text;        // the native line
};

PyTraceEvent event_of(const TraceEvent& e) {
  static constexpr const char* kKinds[] = {"frame", "pin", "fault", "load", "advance", "axis", "stops", "supply"};
  PyTraceEvent p;
  p.kind = kKinds[static_cast<int>(e.kind)];
  p.tick = e.tick;
  p.duration = e.duration;
  p.mosi = py::bytes(reinterpret_cast<const char*>(e.mosi.data()), e.mosi.size());
  p.miso = e.miso.empty() ? py::object(py::none()) : py::object(py::bytes(reinterpret_cast<const char*>(e.miso.data()), e.miso.size()));
  for (std::size_t i = 0; i < e.miso.size(); ++i) p.miso_known.push_back(e.miso_byte_known(i));
  p.chip = e.chip;
  // An SW level the axis drove (an observation) is "SW_AXIS"; "SW" is the input the host drove.
  p.pin = e.kind != TraceEventKind::pin          ? py::object(py::none())
          : e.pin == TracePin::SW_AXIS ? py::object(py::str("SW_AXIS"))
                                       : py::object(py::str(std::string(to_string(e.pin))));
  p.fault = e.kind == TraceEventKind::fault ? py::object(py::str(std::string(to_string(e.fault)))) : py::object(py::none());
  p.value = e.value;
  p.line = e.line;
  p.source_time = e.has_source_time() ? py::object(py::float_(e.source_time)) : py::object(py::none());
  p.text = NativeTraceWriter::format_event(e);
  return p;
}

/// decode()'s answer: the counts and the log.
struct DecodeResult {
  DecodeSummary summary;
  std::string text;
  std::string number_from, numbering;  // how the log counts the chips: "miso"/"mosi", and in words
};

/// replay()'s answer: the replay's, and how its reports count the chips.
struct PyReplayResult : ReplayResult {
  std::string number_from, numbering;
};

/// A number_from= argument: "miso" or "mosi" (ValueError naming the argument otherwise).
NumberFrom number_from_arg(const std::string& text) {
  try {
    return parse_number_from(text);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(std::string("number_from: ") + e.what());
  }
}

}  // namespace

void bind_trace(py::module_& m) {
  // TraceError: a malformed input, with its file and line.
  static py::exception<TraceError> trace_error(m, "TraceError", PyExc_ValueError);
  trace_error.doc() = "A malformed trace: .file and .line say where (line 0: the file as a whole).";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const TraceError& e) {
      py::object exc = py::handle(trace_error.ptr())(e.what());
      exc.attr("file") = e.file();
      exc.attr("line") = e.line();
      PyErr_SetObject(trace_error.ptr(), exc.ptr());
    }
  });

  py::class_<PyTraceEvent>(m, "TraceEvent", "One event of a trace: a CS frame, a pin level or a backdoor fault.")
      .def_readonly("kind", &PyTraceEvent::kind,
                    "\"frame\", \"pin\", \"fault\", \"load\" (an axis load change: see .text), \"advance\" (time moved on),\n"
                    "\"axis\" (an axis attached or removed), \"stops\" (its hard stops moved) or \"supply\" (its motor supply changed)")
      .def_readonly("tick", &PyTraceEvent::tick, "frame: CS falling edge; pin/fault: when (250 ns ticks)")
      .def_readonly("duration", &PyTraceEvent::duration, "frame: ticks from CS falling to rising edge")
      .def_property_readonly("end", [](const PyTraceEvent& e) { return e.tick + e.duration; }, "frame: the CS rising edge")
      .def_readonly("mosi", &PyTraceEvent::mosi, "frame: bytes the host sent")
      .def_readonly("miso", &PyTraceEvent::miso, "frame: bytes received, or None when the trace has none")
      .def_readonly("miso_known", &PyTraceEvent::miso_known, "frame: for each MISO byte, whether the trace knows it")
      .def_readonly("chip", &PyTraceEvent::chip, "pin/fault: the chip (0 drives MISO)")
      .def_readonly("pin", &PyTraceEvent::pin, "pin: SW, STCK, STBY, BUSY, FLAG, or SW_AXIS (the SW level the axis drove, an observation)")
      .def_readonly("fault", &PyTraceEvent::fault, "fault: UVLO, UVLO_ADC, OCD, STALL_A, STALL_B, THERMAL or ADCIN")
      .def_readonly("value", &PyTraceEvent::value, "pin: level 0/1; fault: on/off, Thermal number or ADC code")
      .def_readonly("line", &PyTraceEvent::line, "line in the source file (0 = none)")
      .def_readonly("source_time", &PyTraceEvent::source_time, "seconds as in the source file, or None")
      .def("__str__", [](const PyTraceEvent& e) { return e.text; })
      .def("__repr__", [](const PyTraceEvent& e) { return "TraceEvent(" + e.text + ")"; });

  py::class_<Trace, std::shared_ptr<Trace>>(m, "Trace", R"(A whole trace in memory: CS frames, pin events and faults in time order.

Trace.load(path) reads any format the l6470emu program reads (native, Saleae CSV, umockdev
.ioctl, ftrace text, sigrok JSON; VCD and .sr through sigrok-cli); Trace.parse(text) reads
text; a Chain made with record=True gives one as Chain.trace.)")
      .def(py::init<>(), "An empty trace.")
      .def_static(
          "load",
          [](py::handle path, py::object format, std::string select, py::handle max_frames) {
            const std::string p = path_from(path, "path");
            TraceInputOptions options;
            options.format = format_arg(format);
            options.import.select = select;
            options.import.max_frames = max_frames_arg(max_frames);
            py::gil_scoped_release unlocked;
            return std::make_shared<Trace>(TraceFile(p, options).load());
          },
          py::arg("path"), py::arg("format") = py::none(), py::arg("select") = "", py::kw_only(),
          py::arg("max_frames") = kDefaultMaxTraceFrames,
          "Reads a trace file; format (\"native\", \"saleae\", \"umockdev\", \"ftrace\", \"sigrok\", \"vcd\") is "
          "recognised from the content when None; select picks one stream of a file that holds several. A file "
          "holding more than max_frames frames (native repeat lines counted as the frames they stand for; 0: no "
          "limit) is refused with a TraceError.")
      .def_static(
          "parse",
          [](const std::string& text, std::string name, py::object format, py::handle max_frames) {
            TraceFormat f = format_arg(format);
            if (f == TraceFormat::unknown) f = detect_trace_format(text, name);
            if (f == TraceFormat::unknown)
              throw TraceError(name, 0, "unknown trace format (native, Saleae CSV, umockdev .ioctl, ftrace text, sigrok JSON)");
            if (f == TraceFormat::vcd) throw TraceError(name, 0, "a VCD capture needs sigrok-cli: use Trace.load(path)");
            ImportOptions options;
            options.max_frames = max_frames_arg(max_frames);
            return std::make_shared<Trace>(import_trace(text, name, f, options));
          },
          py::arg("text"), py::arg("name") = "<text>", py::arg("format") = py::none(), py::kw_only(),
          py::arg("max_frames") = kDefaultMaxTraceFrames,
          "Reads a trace from text (any text format; recognised from the content when format is None); at most "
          "max_frames frames (0: no limit).")
      .def("save", [](const Trace& t, py::handle path) {
             const std::string p = path_from(path, "path");
             const std::string text = to_native_text(t);
             TraceFileWriter out(p);  // errors: "PATH: cannot create: REASON", "PATH: write failed: REASON"
             out.write(text);
             out.close();
           },
           py::arg("path"), "Writes the trace as a native trace file (gzip-compressed when the name ends in .gz).")
      .def("to_native", [](const Trace& t) { return to_native_text(t); }, "The trace as native text.")
      .def("__len__", &Trace::size, "Number of events.")
      .def("__getitem__",
           [](const Trace& t, long long i) {
             const long long n = static_cast<long long>(t.size());
             if (i < 0) i += n;
             if (i < 0 || i >= n) throw py::index_error("trace event index out of range");
             return event_of(t[static_cast<std::size_t>(i)]);
           })
      .def("__iter__",
           [](const Trace& t) {
             std::vector<PyTraceEvent> all;
             all.reserve(t.size());
             for (std::size_t i = 0; i < t.size(); ++i) all.push_back(event_of(t[i]));
             return py::iter(py::cast(std::move(all)));
           })
      .def_property_readonly("frame_count", &Trace::frame_count, "Number of CS frames.")
      .def_property_readonly(
          "chain", [](const Trace& t) -> py::object {
            if (t.header.chain.empty()) return py::none();
            return py::str(t.header.chain);
          },
          "The chain the trace was taken from (\"3*L6470\"), or None when it does not say.")
      .def_property_readonly("format", [](const Trace& t) { return t.header.format; }, "The format it was read from.")
      .def_property_readonly("name", [](const Trace& t) { return t.header.name; }, "The file name used in messages.")
      .def_property_readonly("notes", [](const Trace& t) { return t.header.notes; }, "Importer remarks.")
      .def("__repr__", [](const Trace& t) {
        return "Trace(" + counted(t.size(), "event") + ", " + counted(t.frame_count(), "frame") + ", chain " +
               (t.header.chain.empty() ? std::string("unknown") : t.header.chain) + ")";
      });

  py::class_<Divergence>(m, "Divergence", "One point where the emulator and a trace disagree.")
      .def_readonly("frame", &Divergence::frame, "1-based frame number")
      .def_readonly("line", &Divergence::line, "line of the trace file")
      .def_readonly("tick", &Divergence::tick, "when, in 250 ns ticks")
      .def_readonly("source_time", &Divergence::source_time, "seconds shown (the capture's time when it has one)")
      .def_readonly("summary", &Divergence::summary, "one line")
      .def_readonly("report", &Divergence::report, "the full report: bytes, where they come from, the chip state")
      .def("__str__", [](const Divergence& d) { return d.report; })
      .def("__repr__", [](const Divergence& d) { return "Divergence(" + d.summary + ")"; });

  py::class_<FirstDivergence>(m, "FirstDivergence",
                              "Where the emulator first gave MISO bytes or a BUSY/FLAG level other than a trace's.")
      .def_readonly("frame", &FirstDivergence::frame, "1-based frame number (for a pin: the last frame before it)")
      .def_readonly("line", &FirstDivergence::line, "line of the trace file (0: none)")
      .def_readonly("repetition", &FirstDivergence::repetition, "repetition of a native repeat line (0: none)")
      .def_readonly("tick", &FirstDivergence::tick, "when, in 250 ns ticks")
      .def_readonly("seconds", &FirstDivergence::seconds, "when, as shown (the capture's own time when it has one)")
      .def_property_readonly(
          "chip", [](const FirstDivergence& d) -> py::object {
            if (d.number == FirstDivergence::kNoChip) return py::none();
            return py::int_(d.number);
          },
          "the chip that differed, numbered as the call's number_from says (None: bytes past the chain's length)")
      .def_readonly("what", &FirstDivergence::what, "what differed: \"MISO byte 1 expected 0x7E, emulated 0x7C\"")
      .def_readonly("summary", &FirstDivergence::summary, "one line: where, when, which chip, what")
      .def("__str__", [](const FirstDivergence& d) { return d.summary; })
      .def("__repr__", [](const FirstDivergence& d) { return "FirstDivergence(" + d.summary + ")"; });

  py::class_<PyReplayResult>(m, "ReplayResult", "What a replay did; true when every captured byte and pin matched.")
      .def_property_readonly("matched", &ReplayResult::matched, "every captured MISO byte and pin level matched")
      .def("__bool__", &ReplayResult::matched)
      .def_readonly("frames", &ReplayResult::frames, "frames replayed")
      .def_readonly("bytes_compared", &ReplayResult::bytes_compared, "captured MISO bytes checked")
      .def_readonly("bytes_unknown", &ReplayResult::bytes_unknown, "MISO bytes the trace does not know")
      .def_readonly("pin_checks", &ReplayResult::pin_checks, "BUSY/FLAG observations checked")
      .def_readonly("divergent_frames", &ReplayResult::divergent_frames, "frames with a differing MISO byte")
      .def_readonly("pin_mismatches", &ReplayResult::pin_mismatches, "BUSY/FLAG observations that differed")
      .def_readonly("stopped_early", &ReplayResult::stopped_early, "stopped at the first divergence")
      .def_readonly("divergences", &ReplayResult::divergences, "the reported divergences")
      .def_readonly("number_from", &PyReplayResult::number_from, "how the reports count the chips: \"miso\" or \"mosi\"")
      .def_readonly("numbering", &PyReplayResult::numbering, "what the reports' chip numbers mean, in words")
      .def("__repr__", [](const PyReplayResult& r) {
        return std::string("ReplayResult(") + (r.matched() ? "matched" : "diverged") + ", " + counted(r.frames, "frame") +
               ", " + counted(r.bytes_compared, "byte") + " compared)";
      });

  py::class_<DecodeResult>(m, "DecodeResult", "A trace explained: .text is the per-chip log (str() gives it too).")
      .def_property_readonly("frames", [](const DecodeResult& d) { return d.summary.frames; }, "frames decoded")
      .def_property_readonly("commands", [](const DecodeResult& d) { return d.summary.commands; },
                             "complete commands, NOPs excluded")
      .def_property_readonly("answers", [](const DecodeResult& d) { return d.summary.answers; },
                             "GetParam/GetStatus answers")
      .def_property_readonly("diagnostics", [](const DecodeResult& d) { return d.summary.diagnostics; },
                             "protocol diagnostics, shown or not")
      .def_property_readonly("suppressed", [](const DecodeResult& d) { return d.summary.suppressed; },
                             "diagnostics not shown (max_repeats)")
      .def_property_readonly("answer_mismatches", [](const DecodeResult& d) { return d.summary.answer_mismatches; },
                             "captured answers the emulator would give differently")
      .def_property_readonly(
          "divergence", [](const DecodeResult& d) -> py::object {
            if (!d.summary.divergence.found) return py::none();
            return py::cast(d.summary.divergence);
          },
          "None when the emulator gives every captured MISO byte and BUSY/FLAG level; else where it first does "
          "not (a FirstDivergence; the log shows a banner there: what follows is the emulator's model)")
      .def_property_readonly("frames_diverged", [](const DecodeResult& d) { return d.summary.frames_diverged; },
                             "frames whose captured MISO the emulator does not give")
      .def_property_readonly("pins_diverged", [](const DecodeResult& d) { return d.summary.pins_diverged; },
                             "BUSY/FLAG observations the emulator does not reproduce")
      .def_readonly("text", &DecodeResult::text, "the log, one line per command, answer or diagnostic")
      .def_readonly("number_from", &DecodeResult::number_from, "how the log counts the chips: \"miso\" or \"mosi\"")
      .def_readonly("numbering", &DecodeResult::numbering, "what the log's chip numbers mean, in words")
      .def("__str__", [](const DecodeResult& d) { return d.text; })
      .def("__repr__", [](const DecodeResult& d) {
        return "DecodeResult(" + counted(d.summary.frames, "frame") + ", " + counted(d.summary.commands, "command") + ", " +
               counted(d.summary.diagnostics, "diagnostic") + ")";
      });

  m.def(
      "replay",
      [](py::handle trace, py::handle chain, py::handle format, bool keep_going, std::size_t max_reports,
         bool compare_pins, const std::string& number_from, py::handle max_frames, py::handle board) {
        ReplayOptions o;
        o.number_from = number_from_arg(number_from);
        const Source s = source_of(trace, chain, format, "", max_frames_arg(max_frames), board);
        o.keep_going = keep_going;
        o.max_reports = max_reports;
        o.compare_pins = compare_pins;
        PyReplayResult result;
        result.number_from = to_string(o.number_from);
        result.numbering = describe_numbering(o.number_from);
        py::gil_scoped_release unlocked;
        Chain c = s.world.make_chain();
        auto reader = s.reader();
        static_cast<ReplayResult&>(result) = replay_trace(*reader, c, o);
        return result;
      },
      py::arg("trace"), py::arg("chain") = py::none(), py::kw_only(), py::arg("format") = py::none(),
      py::arg("keep_going") = false, py::arg("max_reports") = 100, py::arg("compare_pins") = true,
      py::arg("number_from") = "miso", py::arg("max_frames") = kDefaultMaxTraceFrames, py::arg("board") = py::none(),
      R"(Drives a trace's MOSI into a fresh emulated chain with the captured timing and compares every
MISO byte (and BUSY/FLAG observation). trace: a Trace or a file path. chain: the chain
(default: the trace's own description; for a file without one, guessed from its frame lengths),
chip 0 at the MISO end as in trace files: variants ("3*L6470") or the board description of one
chain with its axes ("chips=L6470 axis.0=stops=0..256000,switch=home@0"); board: instead, the path
of a file holding such a description. number_from: which end the reports call chip 0, "miso"
(chip 0 drives MISO, the default) or "mosi" (chip 0 reads the host's MOSI). max_frames: the
most frames a trace file may hold (native repeat lines counted as the frames they stand for;
0: no limit); a file asking for more raises TraceError at once.)");

  m.def(
      "decode",
      [](py::handle trace, py::handle chain, py::handle format, bool show_nops, std::size_t max_repeats,
         py::object only_chip, const std::string& number_from, py::handle max_frames, py::handle board) {
        DecodeOptions o;
        o.number_from = number_from_arg(number_from);
        const Source s = source_of(trace, chain, format, "", max_frames_arg(max_frames), board);
        o.show_nops = show_nops;
        o.max_repeats = max_repeats;
        if (!only_chip.is_none())
          o.only_chip = static_cast<int>(int_in_range(only_chip, "only_chip", 0, static_cast<long long>(s.chips()) - 1));
        DecodeResult result;
        result.number_from = to_string(o.number_from);
        result.numbering = describe_numbering(o.number_from);
        {
          py::gil_scoped_release unlocked;
          std::ostringstream text;
          Chain c = s.world.make_chain();
          auto reader = s.reader();
          result.summary = decode_trace(*reader, c, text, o);
          result.text = text.str();
        }
        return result;
      },
      py::arg("trace"), py::arg("chain") = py::none(), py::kw_only(), py::arg("format") = py::none(),
      py::arg("show_nops") = false, py::arg("max_repeats") = 10, py::arg("only_chip") = py::none(),
      py::arg("number_from") = "miso", py::arg("max_frames") = kDefaultMaxTraceFrames, py::arg("board") = py::none(),
      R"(Explains a trace: every command and answer per chip, with protocol diagnostics (as `l6470emu decode`).
chain, board: the world it runs through, as for replay(). The result's divergence says where the
emulator first parts from the trace (None: nowhere); the log marks it with a banner.
number_from: which end the log calls chip 0, "miso" (chip 0 drives MISO, the default) or "mosi"
(chip 0 reads the host's MOSI); only_chip is a number in the same convention. max_frames: as
for replay().)");
}

}  // namespace l6470emu::python
