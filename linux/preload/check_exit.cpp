// The preload's side of the driver sanitizer and of mistyped names: the run's end under
// check=error, unknown L6470EMU_* variables, device nodes the board does not have.
#include "linux/preload/check_exit.hpp"
#include "linux/preload/coverage.hpp"
#include "linux/preload/run.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <mutex>
#include <set>
#include <vector>

#include "board/check_rules.hpp"
#include "core/near_miss.hpp"
#include "linux/log.hpp"
#include "board/coverage_file.hpp"
#include "board/run_report.hpp"
#include "linux/preload/state.hpp"

namespace l6470emu::preload {
namespace {

constexpr const char* kKnown[] = {
    "L6470EMU_CHAIN", "L6470EMU_CONFIG", "L6470EMU_SOCKET", "L6470EMU_LOG",         "L6470EMU_TRACE",
    "L6470EMU_SHM",   "L6470EMU_CHECK",  "L6470EMU_CHECK_ALLOW", kCoverageEnv,
    // set by `l6470emu run` for the program it runs (board/run_report.hpp)
    kRunReportEnv, kRunScenarioEnv, kRunTimeoutEnv,
    // read by the l6470emu program, the Python package, the benchmarks and the test suite, not
    // by the preload: known all the same
    "L6470EMU_PYTHON", "L6470EMU_PYTHONPATH", "L6470EMU_PRELOAD", "L6470EMU_PROGRAM", "L6470EMU_SOURCE_DIR",
    "L6470EMU_UPDATE_FIXTURES", "L6470EMU_BUILD", "L6470EMU_SOURCE", "L6470EMU_VM_TIMEOUT", "L6470EMU_VM_KEEP",
    "L6470EMU_WORKLOAD", nullptr};

}  // namespace

void end_run_for_check(const std::string& report) {
  {
    Guard guard;
    // Under `l6470emu run`: the report says why the program ended (run's own exit status for it).
    if (in_run()) end_run(RunEnd::sanitizer, report.substr(0, report.find('\n')));
    finish_coverage();
    raw_write_all(2, report.data(), report.size());
    if (!log_is_stderr()) {
      const std::string first = report.substr(0, report.find('\n'));
      log_line(first.substr(std::min(first.size(), first.find("driver sanitizer"))) + " (the run ends with exit status " +
               std::to_string(kSanitizerExitStatus) + ")");
    }
  }
  _exit(kSanitizerExitStatus);
}

const char* const* known_environment_variables() { return kKnown; }

std::string unknown_environment_variables(char** env) {
  std::string out;
  if (env == nullptr) return out;
  std::vector<std::string> known;
  for (const char* const* k = kKnown; *k; ++k) known.emplace_back(*k);
  for (char** e = env; *e; ++e) {
    if (std::strncmp(*e, "L6470EMU_", 9) != 0) continue;
    const char* eq = std::strchr(*e, '=');
    const std::string name = eq ? std::string(*e, static_cast<std::size_t>(eq - *e)) : std::string(*e);
    bool is_known = false;
    for (const auto& k : known) is_known = is_known || k == name;
    if (is_known) continue;
    const std::string near = closest_names(name, known);
    std::string line = "l6470emu: unknown environment variable " + name.substr(0, 80) + ": nothing reads it";
    if (!near.empty()) line += " (did you mean " + near + "?)";
    line += "; the preload reads L6470EMU_CHAIN, _CONFIG, _SOCKET, _LOG, _TRACE, _SHM, _CHECK, _CHECK_ALLOW\n";
    out += line;
  }
  return out;
}

void note_missing_node(const char* path) {
  if (path == nullptr) return;
  if (std::strncmp(path, "/dev/spidev", 11) != 0 && std::strncmp(path, "/dev/gpiochip", 13) != 0) return;
  static std::mutex m;
  static std::set<std::string>* said = new std::set<std::string>;  // never freed: used until exit
  {
    std::lock_guard lock(m);
    if (said->size() > 1000 || !said->insert(path).second) return;
  }
  std::string list;
  for (const DeviceNode& n : nodes()) list += (list.empty() ? "" : ", ") + n.path;
  log_line("open " + std::string(path).substr(0, 200) + ": the emulated board has no such node (it has " +
           (list.empty() ? std::string("none") : list) + "); the call goes to the system");
}

}  // namespace l6470emu::preload
