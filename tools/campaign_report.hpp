// A fault campaign's report (docs/campaigns.md): the verdict of each rerun, the JSON that holds
// them (deterministic: the same campaign gives the same bytes), shards merged back into the
// whole, the JUnit XML (one testcase per fault and chip) and the printed summary and matrix.
#pragma once

#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "board/scenario.hpp"
#include "tools/run_outcome.hpp"

namespace l6470emu {

/// What one rerun came to.
enum class Verdict : std::uint8_t {
  detected,        ///< the program ended non-zero, or the sanitizer stopped it
  survived,        ///< it exited 0 and the oracle held
  silent_failure,  ///< it exited 0 and the oracle failed: success reported, the chip elsewhere
  hang,            ///< the simulated time limit (or the campaign's wall-clock guard) ended it
  deadlock,        ///< every thread waited in virtual time with nothing to wake them
  crash,           ///< killed by a signal, or it ended without leaving a report
};
inline constexpr Verdict kVerdicts[] = {Verdict::detected, Verdict::survived, Verdict::silent_failure,
                                        Verdict::hang,     Verdict::deadlock, Verdict::crash};
std::string_view to_string(Verdict v);
std::optional<Verdict> verdict_named(std::string_view name);

/// The verdict of a run that came to `outcome` (nullopt: it left none, as a killed `run` does);
/// `wall_killed`: the campaign's wall-clock guard stopped it.
Verdict classify_rerun(const std::optional<RunOutcome>& outcome, bool wall_killed);

/// The verdicts that fail a campaign (--fail-on): a set of verdicts, and whether a `survived`
/// rerun whose driver never read the fault's flag fails too ("survived-unread").
struct FailOn {
  std::set<Verdict> verdicts{Verdict::silent_failure, Verdict::hang, Verdict::deadlock, Verdict::crash};
  bool survived_unread = false;
};
/// Parses "silent_failure,hang,survived-unread"; "" and `error` set for a bad name.
std::optional<FailOn> parse_fail_on(std::string_view list, std::string& error);

/// One rerun's result.
struct RerunResult {
  std::size_t index = 0;       ///< its place in the campaign's whole list (shards keep it)
  std::string fault;
  std::string chain;           ///< "spidev0.0"
  std::size_t chip = 0;        ///< as users number it
  std::string point;           ///< "during_motion"
  Tick tick = 0;
  std::string after_command;   ///< the command the point follows ("" none)
  Verdict verdict = Verdict::survived;
  std::optional<bool> flag_read;  ///< the driver read the fault's flag after it rose (nullopt: no flag tells)
  bool traffic_differs = false;   ///< its SPI traffic from the point on differed from the clean run's
  int exit = 0;                   ///< `run`'s exit status for it
  std::string program;            ///< how the program ended, in words
  std::optional<ScenarioFailure> first_failure;
  std::string reproducer;         ///< the scenario file that reproduces it ("" when kept for none)
  std::string command;            ///< the command that reproduces it
  bool fails(const FailOn& on) const;
};

/// The whole report (or a shard of it).
struct CampaignReport {
  std::vector<std::string> program;
  std::string board;             ///< --board FILE or --chain DESC, as given
  std::string scenario;          ///< the scenario file ("" none)
  std::string oracle;            ///< "scenario" or "clean_run"
  std::vector<std::string> faults;
  std::string points;            ///< "phases" or "every-command"
  Tick clean_end_tick = 0;
  Tick rerun_timeout_ticks = 0;
  std::size_t total = 0;         ///< reruns in the whole campaign
  std::optional<std::pair<unsigned, unsigned>> shard;  ///< (K, N) of a shard
  bool complete = true;          ///< every rerun it was to run ran (false: stopped by a signal)
  std::vector<RerunResult> reruns;  ///< by index
};

/// The report as JSON (keys in a fixed order; no times of the host, no temporary paths).
std::string campaign_json(const CampaignReport& r);
/// Reads campaign_json's form; nullopt and `error` (one line) when it is not that.
std::optional<CampaignReport> parse_campaign_json(std::string_view text, std::string& error);
/// Joins shards of one campaign into the report one machine would have written; nullopt and
/// `error` when they are not shards of the same campaign or overlap.
std::optional<CampaignReport> merge_campaign_reports(const std::vector<CampaignReport>& parts, std::string& error);

/// "48 reruns: 12 detected, 29 survived, 5 silent_failure, 2 hang" (verdicts with none left out).
std::string campaign_summary(const CampaignReport& r);
/// The matrix of fault × point per chip, a legend and every failing rerun's command.
std::string campaign_matrix(const CampaignReport& r, const FailOn& on);
/// JUnit XML: one testcase per (fault, chip), named the same whatever the verdict; a failure
/// lists the reruns that fail `on`, each with its reproducing command.
std::string campaign_junit(const CampaignReport& r, const FailOn& on);

}  // namespace l6470emu
