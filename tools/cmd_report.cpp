// `l6470emu report`: the inputs checked (each bad one a line and exit 2) before any work, the
// recordings of a run of several chains found from the path it recorded to, the page's data
// extracted, the page written to a temporary file beside the output and renamed.
#include "tools/cmd_report.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <deque>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "board/board_config.hpp"
#include "board/coverage_file.hpp"
#include "core/counted.hpp"
#include "tools/cli_errors.hpp"
#include "tools/output_check.hpp"
#include "tools/report_data.hpp"
#include "tools/report_page.hpp"
#include "tools/run_recordings.hpp"

namespace l6470emu {
namespace {

std::string directory_of(const std::string& path) {
  const auto slash = path.rfind('/');
  return slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
}

/// Writes `text` to a new file beside `path` and renames it over `path`; "" or why not.
std::string write_atomically(const std::string& path, const std::string& text) {
  std::string temp = directory_of(path) + "/.l6470emu-report-XXXXXX";
  const int fd = mkstemp(temp.data());
  if (fd < 0) return "cannot create a file in " + quoted_text(directory_of(path));
  std::size_t at = 0;
  bool ok = true;
  while (ok && at < text.size()) {
    const ssize_t w = write(fd, text.data() + at, text.size() - at);
    ok = w > 0;
    if (ok) at += static_cast<std::size_t>(w);
  }
  ok = fchmod(fd, 0644) == 0 && ok;
  ok = close(fd) == 0 && ok;
  if (!ok || std::rename(temp.c_str(), path.c_str()) != 0) {
    unlink(temp.c_str());
    return "cannot write " + quoted_text(path);
  }
  return "";
}

}  // namespace

int run_report(const ReportArgs& args, std::ostream& err, const std::string& who) {
  const std::string me = "l6470emu " + who + ": ";
  try {
    if (!report_page_available()) {
      err << me << "this l6470emu was built without the charting library (Debian's libjs-dygraphs): install it and "
                   "build again\n";
      return kTraceBadInput;
    }
    std::vector<std::string> traces;
    for (const std::string& t : args.traces) {
      const std::vector<ChainRecording> found = find_run_recordings(t);
      if (found.empty()) traces.push_back(t);
      for (const ChainRecording& r : found) traces.push_back(r.path);
    }
    if (traces.empty()) {
      err << me << "give the run's trace (or one per chain)\n";
      return kTraceBadInput;
    }
    std::vector<std::string> inputs = traces;
    inputs.insert(inputs.end(), args.coverage.begin(), args.coverage.end());
    if (!args.campaign.empty()) inputs.push_back(args.campaign);
    if (const std::string why = output_problem(args.output, inputs); !why.empty()) {
      err << me << "cannot write " << quoted_text(args.output) << ": " << why << "\n";
      return kTraceBadInput;
    }
    ReportOptions options;
    options.number_from = number_from_option(args.number_from);
    options.title = args.title;
    const bool shown = args.traces_shown.size() == traces.size();
    if (options.title.empty() && shown)
      for (std::size_t k = 0; k < traces.size(); ++k) options.title += (k ? ", " : "") + args.traces_shown[k];
    // Coverage and campaign first: a foreign file is refused before the trace is read.
    std::optional<CoverageData> coverage;
    for (const std::string& path : args.coverage) {
      if (!coverage) coverage.emplace();
      coverage->merge(read_coverage_file(path));
    }
    std::optional<CampaignReport> campaign = args.campaign_report;
    if (!campaign && !args.campaign.empty()) {
      std::ifstream in(args.campaign, std::ios::binary);
      if (!in) throw std::runtime_error(quoted_text(args.campaign) + ": cannot be read");
      std::stringstream text;
      text << in.rdbuf();
      std::string error;
      campaign = parse_campaign_json(text.str(), error);
      if (!campaign) throw std::runtime_error(quoted_text(args.campaign) + ": " + error);
    }
    std::deque<TraceFile> files;
    std::deque<TraceWorld> worlds;
    std::vector<ReportRecording> recordings;
    for (const std::string& path : traces) {
      TraceArgs one = args.trace;
      one.path = path;
      files.emplace_back(path, input_options(one));
      worlds.push_back(world_of(one, files.back()));
      print_notes(files.back().header(), err);
      recordings.push_back({files.back(), worlds.back()});
    }
    ReportData data = make_report_data(recordings, options);
    for (std::size_t k = 0; shown && k < data.chains.size(); ++k)
      if (!args.traces_shown[k].empty()) data.chains[k].trace_path = args.traces_shown[k];
    data.coverage = std::move(coverage);
    data.campaign = std::move(campaign);
    std::ostringstream page;
    write_report_page(data, page);
    const std::string html = page.str();
    if (const std::string why = write_atomically(args.output, html); !why.empty()) {
      err << me << why << "\n";
      return kTraceBadInput;
    }
    char size[32];
    std::snprintf(size, sizeof size, "%.1f", static_cast<double>(html.size()) / 1e6);
    err << me << counted(data.frames(), "frame") << ", " << counted(data.chips(), "chip");
    if (data.chains.size() > 1) err << ", " << counted(data.chains.size(), "chain");
    if (const std::uint64_t findings = data.findings(); findings) err << ", " << counted(findings, "finding");
    for (const ReportChain& c : data.chains)
      if (!c.first_divergence.empty())
        err << ", DIVERGED " << (data.chains.size() > 1 ? "on " + c.name + " " : std::string()) << "at "
            << c.first_divergence;
    if (data.summarised())
      err << " (summarised: the " << (data.chains.size() > 1 ? "run" : "trace")
          << " is longer than a page shows one by one)";
    err << " -> " << args.output << " (" << size << " MB)\n";
    return kTraceOk;
  } catch (const std::exception& e) {
    err << me << e.what() << "\n";
    return kTraceBadInput;
  }
}

void add_report_command(CLI::App& app) {
  auto a = std::make_shared<ReportArgs>();
  CLI::App* r = app.add_subcommand(
      "report", "write one self-contained HTML page of a run: the frames each chip decoded, pins, position, speed, "
                "phase drive, registers at a cursor, findings, and the coverage and campaign when given; a run of "
                "several chains is one page with a section per chain (exit 0; 2 = bad input)");
  r->add_option("TRACE", a->traces,
                "the run's trace, or one per chain of a run of several chains (run.spidev0.0.trace "
                "run.spidev0.1.trace), or the path such a run recorded to (run.trace: its chains' traces beside it); "
                "any format decode reads")
      ->required();
  add_trace_reading_options(r, a->trace);
  r->add_option("-o,--output", a->output, "the page to write (.html)")->required();
  r->add_option("--coverage", a->coverage, "interface coverage files of the run (merged), shown on the page");
  r->add_option("--campaign", a->campaign, "a campaign's JSON report (campaign --json), shown as its matrix");
  r->add_option("--title", a->title, "the page's title (default: the traces' names)");
  add_number_from_option(r, a->number_from);
  r->callback([a] {
    if (const int status = run_report(*a, std::cerr); status != 0) throw CLI::RuntimeError(status);
  });
}

}  // namespace l6470emu
