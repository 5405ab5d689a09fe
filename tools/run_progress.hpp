// `l6470emu run`'s progress line: while a long run goes on (past a couple of seconds of wall
// time), a line on a terminal says how far the program got in board time and how many SPI
// messages it exchanged, from the page the program's front keeps (board/run_report.hpp's
// RunProgress; the preload: linux/preload/progress.hpp). Silent when standard error is not a
// terminal, so logs and CI never see it.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "board/run_report.hpp"

namespace l6470emu {

/// The line: "l6470emu run: 12.500000 s of board time, 3456 SPI messages (4 s of wall time)".
std::string format_run_progress(const RunProgress& p, double wall_seconds);

/// The page (a temporary file the program maps) and the line drawn from it.
class RunProgressLine {
 public:
  /// A page for a run whose standard error is a terminal; nullptr otherwise (or when the page
  /// cannot be made: the run goes on without a line).
  static std::unique_ptr<RunProgressLine> on_terminal();
  ~RunProgressLine();  ///< clears the line and removes the file
  RunProgressLine(const RunProgressLine&) = delete;
  RunProgressLine& operator=(const RunProgressLine&) = delete;

  /// "L6470EMU_RUN_PROGRESS=PATH", for the program's environment.
  std::string environment_entry() const;
  /// What the program keeps in the page now.
  RunProgress read() const;
  /// Draws the line once 2 s of wall time have passed, then at most every 500 ms.
  void update();
  /// Takes the line off the screen for good (the program ended: run's own lines follow).
  void finish();

 private:
  RunProgressLine(std::string path, void* page);
  std::string path_;
  void* page_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_{};
  bool drawn_ = false;
  bool finished_ = false;
};

}  // namespace l6470emu
