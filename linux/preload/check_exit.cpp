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
