// `l6470emu report TRACE... [--coverage FILE...] [--campaign FILE.json] -o report.html`: one
// self-contained HTML page per run (tools/report_page.hpp), from the run's recordings (a trace,
// or one per chain of a run of several chains) and, when given, the run's interface coverage
// and a campaign's report. `run --html` and `campaign --html` use it too.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "tools/campaign_report.hpp"
#include "tools/trace_commands.hpp"

namespace CLI {
class App;
}

namespace l6470emu {

/// What `report` takes.
struct ReportArgs {
  /// The recordings: a trace per chain of the run, in the order the page shows them. A path
  /// that is no file but the path a run of several chains recorded to stands for the recordings
  /// it left beside it (find_run_recordings: "run.trace" for "run.spidev0.0.trace" and
  /// "run.spidev0.1.trace").
  std::vector<std::string> traces;
  /// How each trace is read and the world it runs through (--format, --chain, --board...,
  /// applied to every trace); its `path` is not used.
  TraceArgs trace;
  std::vector<std::string> coverage;  ///< coverage files, merged
  std::string campaign;               ///< a campaign's JSON report ("" = none)
  /// A campaign report already in memory (campaign --html), used instead of `campaign`.
  std::optional<CampaignReport> campaign_report;
  std::string output;                 ///< the page to write
  std::string number_from = "miso";
  std::string title;                  ///< "" = the traces' names
  /// How the page names each trace (none, or one per trace; "" = its path): a temporary
  /// recording (run --html without --record, campaign --html) has a name of its own, so that
  /// the same run gives the same page.
  std::vector<std::string> traces_shown;
};

/// Writes the page: 0, or 2 with one line on `err` ("l6470emu report: ...") for bad input (an
/// unreadable or malformed trace, two traces of the same chain, a file that is not a coverage
/// file or a campaign report, an output that cannot be written or is one of the inputs). The
/// page is written beside the output and renamed over it, so a page is never left half
/// written. `who` names the command in messages ("report", "run --html").
int run_report(const ReportArgs& args, std::ostream& err, const std::string& who = "report");

/// Adds `report` to `app`; it ends the program through CLI::RuntimeError when not 0.
void add_report_command(CLI::App& app);

}  // namespace l6470emu
