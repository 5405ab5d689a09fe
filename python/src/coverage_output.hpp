// Where the interface coverage of a Python Board or Chain goes: the coverage file it is merged
// into (board/coverage_file.hpp) when the object is closed, destroyed, or at the interpreter's
// exit, so that nothing met is lost. No Python types here; coverage_bindings.cpp wraps it.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "board/coverage.hpp"

namespace l6470emu::python {

/// What a coverage= argument (or L6470EMU_COVERAGE) asks for.
struct CoverageRequest {
  bool collect = false;  ///< collect coverage at all
  std::string path;      ///< the coverage file, absolute ("" with collect: in memory only)
  std::string origin;    ///< what named the file, for messages ("coverage", "L6470EMU_COVERAGE")
};

/// The coverage file of one Board or Chain. Every live one is known, so that the interpreter's
/// exit (and a pytest session's end) can merge what each has met. Not thread-safe: the GIL
/// serialises callers.
class CoverageOutput {
 public:
  using Source = std::function<CoverageData()>;

  /// Merges what `source` returns into `path` (absolute; checked by the caller) from now on.
  /// `source` must stay valid until this object is destroyed.
  CoverageOutput(std::string path, Source source);
  /// Merges what is new since the last merge; a failure is a line on stderr (nothing to raise to).
  ~CoverageOutput();
  CoverageOutput(const CoverageOutput&) = delete;
  CoverageOutput& operator=(const CoverageOutput&) = delete;

  const std::string& path() const { return path_; }
  /// Merges the data into the file unless it has not changed since the last merge: "" or one
  /// line saying why not (the file left as it was; the next flush tries again).
  std::string flush();

  /// Flushes every live CoverageOutput: the lines of those that failed.
  static std::vector<std::string> flush_all();

 private:
  std::string path_;
  Source source_;
  CoverageData merged_;  // what the file was last given
  bool ever_merged_ = false;
};

}  // namespace l6470emu::python
