// `l6470emu coverage report FILE...` prints interface coverage (a table per variant, the points
// never hit; text, JSON or LCOV) and `coverage merge A B ... -o C` joins coverage files
// (docs/coverage.md).
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

namespace l6470emu {

/// Adds `coverage report` and `coverage merge` to `app`; run() returns the exit status once
/// `app` is parsed and `coverage` was chosen: 0, 1 below --fail-under, 2 for bad input.
class CoverageCommand {
 public:
  explicit CoverageCommand(CLI::App& app);
  std::optional<int> run();

 private:
  int run_report();
  int run_merge();
  CLI::App* cmd_ = nullptr;
  CLI::App* report_ = nullptr;
  CLI::App* merge_ = nullptr;
  std::vector<std::string> inputs_;
  std::string format_ = "text", output_, listing_dir_;
  std::optional<double> fail_under_;
  bool show_missing_ = false;
  std::vector<std::string> merge_inputs_;
  std::string merge_output_;
};

}  // namespace l6470emu
