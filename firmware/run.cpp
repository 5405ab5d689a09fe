// The firmware program under `l6470emu run`: scenario, time limit, report at exit.
#include "firmware/run.hpp"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string_view>

#include "board/run_report.hpp"
#include "board/scenario.hpp"
#include "firmware/runtime.hpp"

extern "C" {
/// Exported by the preload library (linux/preload/run.hpp) when it is loaded into the program,
/// as `l6470emu run` loads it: its own board leaves the run. Returns the process's id for the
/// report (the firmware front knows no processes). Absent without the preload.
long l6470emu_preload_leave_run(void) __attribute__((weak));
}

namespace l6470emu {
namespace {

FirmwareRuntime* g_runtime = nullptr;
std::string* g_report_path = nullptr;  // never freed: read at exit
Tick g_timeout = kNever;
std::int64_t g_pid = 0;
bool g_reported = false;

// Reads a whole file with stdio; false when it cannot be read.
bool read_file(const char* path, std::string& text) {
  std::FILE* f = std::fopen(path, "rb");
  if (!f) return false;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
  const bool ok = std::ferror(f) == 0;
  std::fclose(f);
  return ok;
}

// Writes this process's block once: `cause` and its words (lines).
void report(RunEnd cause, std::string_view detail) {
  if (!g_runtime || g_reported) return;
  g_reported = true;
  RunReport r;
  r.pid = g_pid;
  r.end = cause;
  r.devices = g_runtime->clocked_bytes();
  try {
    r.scenario = g_runtime->finish_scenario(r.outcome);
    r.tick = g_runtime->now();
    if (cause == RunEnd::timeout && detail.empty())
      r.detail.push_back("the simulated time limit " + seconds_text(g_timeout) + " was reached");
    for (std::string& line : detail_lines(detail)) r.detail.push_back(std::move(line));
  } catch (...) {
  }
  if (!g_report_path) return;
  const std::string text = format_run_report(r);
  // Appended in one write (unbuffered): blocks of other processes of the run do not interleave.
  std::FILE* f = std::fopen(g_report_path->c_str(), "ab");
  if (!f) {
    g_runtime->log("the run report " + *g_report_path + " cannot be written");
    return;
  }
  std::setvbuf(f, nullptr, _IONBF, 0);
  std::fwrite(text.data(), 1, text.size(), f);
  std::fclose(f);
}

void report_at_exit() { report(RunEnd::exit, ""); }

}  // namespace

std::string join_run(FirmwareRuntime& runtime) {
  const char* path = std::getenv(kRunReportEnv);
  const char* scenario = std::getenv(kRunScenarioEnv);
  const char* timeout = std::getenv(kRunTimeoutEnv);
  if (!(path && *path) && !(scenario && *scenario) && !(timeout && *timeout)) return "";
  if (timeout && *timeout) {
    char* end = nullptr;
    const unsigned long long t = std::strtoull(timeout, &end, 10);
    if (!end || *end || t == 0) return std::string("l6470emu: ") + kRunTimeoutEnv + " is not a number of ticks";
    g_timeout = static_cast<Tick>(t);
  }
  if (scenario && *scenario) {
    std::string text;
    if (!read_file(scenario, text)) return std::string("l6470emu: the run's scenario ") + scenario + " cannot be read";
    std::string error;
    const auto s = deserialize_scenario(text, error);
    if (!s) return "l6470emu: " + std::string(scenario) + ": " + error;
    try {
      runtime.bind_scenario(*s);
    } catch (const std::exception& e) {
      return std::string("l6470emu: scenario ") + e.what();
    }
  }
  // The program's board is the run's now: the preload's own (built from the same description,
  // never used by a firmware program) neither reports nor ends the program.
  if (l6470emu_preload_leave_run) g_pid = l6470emu_preload_leave_run();
  g_runtime = &runtime;
  if (path && *path) g_report_path = new std::string(path);
  runtime.set_run_limit(g_timeout);
  runtime.set_end_hook([](RunEnd cause, std::string_view detail) { report(cause, detail); });
  std::atexit(report_at_exit);
  return "";
}

}  // namespace l6470emu
