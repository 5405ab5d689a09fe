// The exception a check=error failure travels to Python in (translated into
// l6470emu.SanitizerError with the sanitizer's report by chain_bindings.cpp), and the warning
// a check=warn line becomes (l6470emu.SanitizerWarning).
#pragma once

#include <pybind11/pybind11.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace l6470emu::python {

/// The l6470emu.SanitizerWarning class (a UserWarning).
PyObject* sanitizer_warning();
/// Issues each check=warn line as an l6470emu.SanitizerWarning (the GIL held); throws
/// pybind11::error_already_set when a warnings filter turned one into an error.
void warn_sanitizer_lines(const std::vector<std::string>& lines);

/// A check=error failure on its way to Python; what() is the sanitizer's report.
struct SanitizerFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace l6470emu::python
