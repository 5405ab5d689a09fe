// The exception a check=error failure travels to Python in (translated into
// l6470emu.SanitizerError with the sanitizer's report by chain_bindings.cpp).
#pragma once

#include <stdexcept>

namespace l6470emu::python {

/// A check=error failure on its way to Python; what() is the sanitizer's report.
struct SanitizerFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace l6470emu::python
