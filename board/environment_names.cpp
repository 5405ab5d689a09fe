// The known L6470EMU_* names and the near-miss line for the others.
#include "board/environment_names.hpp"

#include <cstring>
#include <vector>

#include "board/coverage_file.hpp"
#include "board/run_report.hpp"
#include "core/near_miss.hpp"

namespace l6470emu {
namespace {

constexpr const char* kKnown[] = {
    "L6470EMU_CHAIN", "L6470EMU_CONFIG", "L6470EMU_SOCKET", "L6470EMU_LOG",         "L6470EMU_TRACE",
    "L6470EMU_SHM",   "L6470EMU_CHECK",  "L6470EMU_CHECK_ALLOW", kCoverageEnv,
    // set by `l6470emu run` for the program it runs (board/run_report.hpp)
    kRunReportEnv, kRunScenarioEnv, kRunTimeoutEnv, kRunProgressEnv,
    // set by `l6470emu campaign` for the run that forks its reruns (linux/fork_plan.hpp, kForkPlanEnv)
    "L6470EMU_FORK_PLAN",
    // read by the l6470emu program, the Python package, the benchmarks and the test suite, not
    // by the preload: known all the same
    "L6470EMU_PYTHON", "L6470EMU_PYTHONPATH", "L6470EMU_PRELOAD", "L6470EMU_PROGRAM", "L6470EMU_SOURCE_DIR",
    "L6470EMU_UPDATE_FIXTURES", "L6470EMU_BUILD", "L6470EMU_SOURCE", "L6470EMU_VM_TIMEOUT", "L6470EMU_VM_KEEP",
    "L6470EMU_WORKLOAD", "L6470EMU_FUZZ_SEED", "L6470EMU_FUZZ_JOBS", nullptr};

}  // namespace

const char* const* known_environment_variables() { return kKnown; }

std::string unknown_environment_variables(char** env, std::string_view reader) {
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
    line += "; " + std::string(reader) + "\n";
    out += line;
  }
  return out;
}

}  // namespace l6470emu
