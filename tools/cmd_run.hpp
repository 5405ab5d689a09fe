// `l6470emu run`: builds a board, runs an unmodified program against it through the preload
// library (virtual time by default) or the kernel's own device nodes (CUSE, UHID; wall time),
// applies a scenario, and ends with a report, a JUnit file and an exit status a CI reads
// (board/run_report.hpp's RunStatus; docs/scenarios.md).
#pragma once

#include <CLI/CLI.hpp>

#include <optional>

namespace l6470emu {

/// Adds `run` to `app`; run() returns its exit status once `app` is parsed and `run` was chosen.
class RunCommand {
 public:
  explicit RunCommand(CLI::App& app);
  std::optional<int> run();

 private:
  CLI::App* cmd_ = nullptr;
  std::string board_file_, chain_, scenario_file_, time_ = "virtual", nodes_ = "preload", timeout_, junit_, record_, outcome_, coverage_,
      html_, wall_timeout_ = "3600";
  bool verbose_ = false;
  std::vector<std::string> program_;
};

}  // namespace l6470emu
