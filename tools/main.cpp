// The l6470emu command-line program: subcommands over the emulator library.
#include <CLI/CLI.hpp>
#include <fstream>
#include <iostream>
#include <sstream>

#include "tools/cli_errors.hpp"
#include "tools/cmd_plot.hpp"
#include "tools/cmd_report.hpp"
#include "tools/cmd_units.hpp"
#include "tools/cmd_campaign.hpp"
#include "tools/cmd_coverage.hpp"
#include "tools/cmd_run.hpp"
#include "tools/cmd_serve.hpp"
#include "tools/demo.hpp"
#include "tools/tables.hpp"
#include "tools/trace_commands.hpp"

namespace {

int update_readme(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    std::cerr << "l6470emu: cannot read " << path << "\n";
    return 1;
  }
  std::stringstream text;
  text << in.rdbuf();
  const std::string fresh = l6470emu::refresh_generated_blocks(text.str());
  if (fresh == text.str()) return 0;
  std::ofstream out(path, std::ios::trunc);
  out << fresh;
  if (!out) {
    std::cerr << "l6470emu: cannot write " << path << "\n";
    return 1;
  }
  std::cout << "updated the generated tables in " << path << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"l6470emu: register-level emulator of the ST L6470-family SPI motion engines", "l6470emu"};
  app.set_version_flag("--version", std::string("l6470emu ") + L6470EMU_VERSION);
  app.require_subcommand(1);

  std::size_t chips = 3;
  unsigned seconds = 10;
  auto* demo = app.add_subcommand("demo", "drive an emulated daisy chain and print what the chips did");
  demo->add_option("--chips", chips, "chips in the chain (1..256)")->check(CLI::Range(1, 256));
  demo->add_option("--seconds", seconds, "virtual seconds to run at most")->check(CLI::Range(1, 3600));

  std::string table = "l6470-registers";
  std::string readme;
  auto* tables = app.add_subcommand("tables", "print the tables the model uses, as Markdown");
  tables->add_option("--table", table, "which table")
      ->check(l6470emu::one_of({"l6470-registers", "l6470-status", "commands", "variant-registers", "variant-status",
                                "variant-differences", "sanitizer-rules", "units", "l6474-registers", "l6474-status",
                                "l6474-commands"}));
  tables->add_option("--update-readme", readme,
                     "rewrite the generated blocks of this Markdown file instead (docs/reference/tables.md, docs/linux.md, "
                     "docs/l6474.md)");

  l6470emu::ServeCommands serve_commands(app);  // serve, ctl
  l6470emu::RunCommand run_command(app);         // run
  l6470emu::CampaignCommand campaign_command(app);  // campaign, campaign merge
  l6470emu::CoverageCommand coverage_command(app);  // coverage report, coverage merge
  l6470emu::add_trace_commands(app);             // replay, decode, convert
  l6470emu::add_plot_command(app);               // plot (python3 -m l6470emu.plot)
  l6470emu::add_units_command(app);              // units (register values <-> step/s, mA, ...)
  l6470emu::add_report_command(app);             // report (one HTML page per run)

  // Every usage error: one line, a suggestion for a near miss, exit status 2.
  if (auto status = l6470emu::parse_command_line(app, argc, argv, std::cout, std::cerr)) return *status;
  if (auto status = serve_commands.run()) return *status;
  if (auto status = run_command.run()) return *status;
  if (auto status = campaign_command.run()) return *status;
  if (auto status = coverage_command.run()) return *status;
  if (*demo) return l6470emu::run_demo(chips, seconds, std::cout);
  if (*tables) {
    if (!readme.empty()) return update_readme(readme);
    std::cout << l6470emu::generated_block(table);
  }
  return 0;
}
