// Interface coverage for Python (docs/coverage-python.md): the coverage= argument of Board and
// Chain (and L6470EMU_COVERAGE, its default), coverage as a dict, the text and JSON reports of
// coverage files, and the merge of every live object's coverage at the interpreter's exit.
#include <pybind11/stl.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "board/coverage_file.hpp"
#include "board/coverage_report.hpp"
#include "bindings.hpp"
#include "convert.hpp"
#include "coverage_output.hpp"

namespace l6470emu::python {
namespace {

/// The files of a files= argument: one path, or an iterable of them.
std::vector<std::string> paths_from(py::handle files) {
  std::vector<std::string> out;
  if (py::isinstance<py::str>(files) || py::hasattr(files, "__fspath__")) {
    out.push_back(path_from(files, "files"));
  } else if (py::isinstance<py::iterable>(files) && !py::isinstance<py::bytes>(files)) {
    for (py::handle f : files) out.push_back(path_from(f, "files"));
  } else {
    throw py::type_error("files: a path (str or os.PathLike) or a list of them is needed");
  }
  if (out.empty()) throw py::value_error("files: no coverage file named");
  return out;
}

/// The union of the coverage files; ValueError with the file's line when one cannot be read.
CoverageData read_files(py::handle files) {
  CoverageData data;
  for (const std::string& path : paths_from(files)) {
    try {
      data.merge(read_coverage_file(path));
    } catch (const std::runtime_error& e) {
      throw py::value_error(e.what());
    }
  }
  return data;
}

void print_failures(const std::vector<std::string>& lines) {
  for (const std::string& why : lines) std::fprintf(stderr, "l6470emu: coverage not written: %s\n", why.c_str());
}

}  // namespace

CoverageRequest coverage_request_from(py::handle arg) {
  CoverageRequest r;
  if (arg.is_none()) {
    const char* env = std::getenv(kCoverageEnv);
    if (env == nullptr || *env == '\0') return r;
    r.path = env;
    r.origin = kCoverageEnv;
  } else if (PyBool_Check(arg.ptr())) {
    r.collect = arg.ptr() == Py_True;  // True: in memory only (coverage_data())
    return r;
  } else {
    r.path = path_from(arg, "coverage");
    r.origin = "coverage";
  }
  r.collect = true;
  if (r.path.empty()) throw py::value_error(r.origin + ": the coverage file name is empty");
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(r.path, ec);  // a later chdir changes nothing
  if (!ec) r.path = absolute.lexically_normal().string();
  if (const std::string why = check_coverage_output(r.path); !why.empty()) throw py::value_error(r.origin + ": " + why);
  return r;
}

py::object coverage_dict(const CoverageData& data) {
  return py::module_::import("json").attr("loads")(data.to_json());
}

void bind_coverage(py::module_& m) {
  m.def(
      "coverage_report",
      [](py::handle files, const std::string& format, bool show_missing) {
        const CoverageData data = read_files(files);
        if (format == "text") return coverage_text(data, show_missing);
        if (format == "json") return coverage_json_report(data);
        throw py::value_error("format " + format + ": \"text\" or \"json\"");
      },
      py::arg("files"), py::kw_only(), py::arg("format") = "text", py::arg("show_missing") = false,
      "The report of one coverage file or the union of several (a path or a list of paths), as `l6470emu "
      "coverage report` prints it: format \"text\" (a table per variant; show_missing lists every point never "
      "hit) or \"json\". ValueError names a file that cannot be read.");
  m.def(
      "coverage_total",
      [](py::handle files) {
        const CoverageCount total = coverage_total(read_files(files));
        return py::make_tuple(total.hit, total.total);
      },
      py::arg("files"),
      "(hit, total): the points met and the points there are, over every variant of the coverage file(s) "
      "(rules broken aside), as the report's total.");
  m.def(
      "_coverage_problem", [](py::handle path) { return check_coverage_output(path_from(path, "path")); },
      py::arg("path"), "Why `path` cannot take coverage (\"\" when it can): the pytest plugin's start-up check.");
  m.def(
      "_flush_coverage", [] { return CoverageOutput::flush_all(); },
      "Merges what every live Board and Chain collecting coverage has met into its file; the lines of the failures.");
  // Objects never closed nor destroyed before the interpreter ends still give their coverage.
  py::module_::import("atexit").attr("register")(py::cpp_function([] { print_failures(CoverageOutput::flush_all()); }));
}

}  // namespace l6470emu::python
