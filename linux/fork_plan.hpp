// A campaign's snapshot plan, as `l6470emu campaign` hands it to the preload of the program it
// runs once more (L6470EMU_FORK_PLAN names the file): at each rerun's injection tick, a program
// that is single-threaded there forks, and the child goes on as that rerun — its fault and oracle
// steps added to the scenario, its output, run report and recordings in the rerun's own
// directory — so that a rerun costs its remainder, not a whole run (docs/campaigns.md,
// § Snapshots). This file is the plan's text and the names of the files in a rerun's directory.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/tick.hpp"

namespace l6470emu {

/// The environment variable that names the plan file.
inline constexpr const char* kForkPlanEnv = "L6470EMU_FORK_PLAN";

/// The files of one rerun's directory.
namespace fork_files {
inline constexpr const char* steps = "steps";              ///< the steps the child adds (board/scenario.hpp's exchange form)
inline constexpr const char* output = "output.txt";        ///< the child's standard output and error
inline constexpr const char* report = "report";            ///< its run report blocks (board/run_report.hpp)
inline constexpr const char* ended = "ended";              ///< "PID WSTATUS", written once the child was waited for
inline constexpr const char* wall_killed = "wall_killed";  ///< present when it was ended at the wall-clock limit
inline constexpr const char* not_forked = "not_forked";    ///< why no child was forked (then it is rerun from the start)
}  // namespace fork_files

/// What the program does at each injection tick.
struct ForkPlan {
  struct Job {
    Tick tick = 0;    ///< the fault's tick: the child is forked when the board gets there
    std::string dir;  ///< the rerun's directory (absolute)
  };
  unsigned children = 1;         ///< children running at once, at most
  std::int64_t wall_ns = 0;      ///< wall-clock limit of one child (0: none)
  /// The run's recordings (absolute paths): each child goes on recording into a copy of each,
  /// DIR/<its file name>.
  std::vector<std::string> recordings;
  std::vector<Job> jobs;         ///< in order of tick
};

/// The plan's text: "l6470emu fork plan 1", then "children N", "wall_ns N", "record PATH" and
/// "job TICK DIR" lines. Paths must not hold a newline.
std::string format_fork_plan(const ForkPlan& plan);
/// Reads it back; nullopt (and `error`) when it is not such a text.
std::optional<ForkPlan> parse_fork_plan(std::string_view text, std::string& error);

}  // namespace l6470emu
