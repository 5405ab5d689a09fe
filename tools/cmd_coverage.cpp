// `l6470emu coverage`: reports and merges of interface coverage files.
#include "tools/cmd_coverage.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <filesystem>
#include <cstring>
#include <cstdlib>
#include <fstream>
#include <iostream>

#include "board/coverage_file.hpp"
#include "board/coverage_report.hpp"
#include "tools/cli_errors.hpp"
#include "tools/output_check.hpp"

namespace l6470emu {

namespace {

std::string directory_of(const std::string& path) {
  const auto slash = path.rfind('/');
  return slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
}

/// Every input merged, or one line on stderr and nullopt.
std::optional<CoverageData> read_inputs(const std::vector<std::string>& inputs, const char* sub) {
  CoverageData all;
  for (const std::string& path : inputs) {
    try {
      all.merge(read_coverage_file(path));
    } catch (const std::exception& e) {
      std::cerr << "l6470emu coverage " << sub << ": " << e.what() << "\n";
      return std::nullopt;
    }
  }
  return all;
}

}  // namespace

CoverageCommand::CoverageCommand(CLI::App& app) {
  cmd_ = app.add_subcommand("coverage", "report or merge interface coverage files (docs/coverage.md)");
  cmd_->require_subcommand(1);
  report_ = cmd_->add_subcommand("report", "print what the runs of coverage FILEs met of each chip's interface");
  report_->add_option("files", inputs_, "coverage files (L6470EMU_COVERAGE=FILE, run --coverage FILE, ...)")->required();
  report_->add_option("--format", format_, "text (a table per variant), json, or lcov (for genhtml and CI viewers)")
      ->check(one_of({"text", "json", "lcov"}));
  report_->add_option("-o,--output", output_, "write the report here instead of standard output");
  report_->add_option("--listing-dir", listing_dir_,
                      "with --format lcov: where the interface listings go (default: l6470emu-interface beside the output)");
  report_->add_option("--fail-under", fail_under_, "exit 1 when the total is below PCT percent")->check(CLI::Range(0.0, 100.0));
  report_->add_flag("--show-missing", show_missing_, "list every point never hit");
  merge_ = cmd_->add_subcommand("merge", "join coverage files into one");
  merge_->add_option("files", merge_inputs_, "coverage files")->required();
  merge_->add_option("-o,--output", merge_output_, "the joined file (never one of the inputs)")->required();
}

std::optional<int> CoverageCommand::run() {
  if (!*cmd_) return std::nullopt;
  if (*report_) return run_report();
  return run_merge();
}

int CoverageCommand::run_report() {
  auto fail = [](const std::string& line) {
    std::cerr << "l6470emu coverage report: " << line << "\n";
    return kUsageError;
  };
  if (!output_.empty())
    if (const std::string why = output_problem(output_, inputs_); !why.empty()) return fail("cannot write " + output_ + ": " + why);
  if (!listing_dir_.empty() && format_ != "lcov") return fail("--listing-dir goes with --format lcov");
  const auto data = read_inputs(inputs_, "report");
  if (!data) return kUsageError;
  std::string text;
  if (format_ == "text") {
    text = coverage_text(*data, show_missing_);
  } else if (format_ == "json") {
    text = coverage_json_report(*data);
  } else {
    const std::string dir = absolute_path(!listing_dir_.empty() ? listing_dir_
                                     : output_.empty()    ? std::string("l6470emu-interface")
                                                          : directory_of(absolute_path(output_)) + "/l6470emu-interface");
    const CoverageLcov lcov = coverage_lcov(*data, dir);
    if (mkdir(dir.c_str(), 0755) != 0 && errno != EEXIST) return fail("cannot make " + dir + ": " + std::strerror(errno));
    for (const auto& [path, listing] : lcov.listings) {
      if (const std::string why = output_problem(path, inputs_); !why.empty()) return fail("cannot write " + path + ": " + why);
      if (!write_whole_file(path, listing)) return fail("cannot write " + path);
    }
    text = lcov.tracefile;
  }
  if (output_.empty()) {
    std::cout << text << std::flush;
  } else if (!write_whole_file(output_, text)) {
    return fail("cannot write " + output_);
  }
  if (fail_under_) {
    const CoverageCount total = coverage_total(*data);
    if (!total.at_least(*fail_under_)) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "l6470emu coverage report: total %.1f%% is below --fail-under %g\n", total.percent(), *fail_under_);
      std::cerr << buf;
      return 1;
    }
  }
  return 0;
}

int CoverageCommand::run_merge() {
  auto fail = [](const std::string& line) {
    std::cerr << "l6470emu coverage merge: " << line << "\n";
    return kUsageError;
  };
  if (const std::string why = output_problem(merge_output_, merge_inputs_); !why.empty())
    return fail("cannot write " + merge_output_ + ": " + why);
  const auto data = read_inputs(merge_inputs_, "merge");
  if (!data) return kUsageError;
  if (!write_whole_file(merge_output_, data->to_json())) return fail("cannot write " + merge_output_);
  return 0;
}

}  // namespace l6470emu
