// `l6470emu campaign`: runs a program once clean under `run`, then once per (fault, chip,
// injection point) with the fault raised at its exact tick, and judges each rerun
// (docs/campaigns.md); `campaign merge` joins the JSON of shards.
#pragma once

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

namespace l6470emu {

/// Adds `campaign` (and `campaign merge`) to `app`; run() returns its exit status once `app` is
/// parsed and `campaign` was chosen.
class CampaignCommand {
 public:
  explicit CampaignCommand(CLI::App& app);
  std::optional<int> run();

 private:
  int run_campaign();
  int run_merge();

  CLI::App* cmd_ = nullptr;
  CLI::App* merge_ = nullptr;
  std::string board_file_, chain_, scenario_file_, faults_ = "all", points_ = "phases", shard_, json_, junit_, fail_on_,
      timeout_, reproducers_ = "failing", snapshots_ = "yes", only_chips_, only_points_, coverage_, html_;
  double wall_timeout_s_ = 60;
  unsigned jobs_ = 0;
  bool list_ = false;
  std::vector<std::string> program_;
  std::vector<std::string> merge_inputs_;
  std::string merge_output_;
};

}  // namespace l6470emu
