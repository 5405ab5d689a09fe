// The preload's side of `l6470emu run`: scenario, time limit, report.
#include "linux/preload/run.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "linux/log.hpp"
#include "linux/preload/coverage.hpp"
#include "linux/preload/fork_server.hpp"
#include "linux/preload/real.hpp"
#include "linux/preload/state.hpp"
#include "linux/process_waits.hpp"

namespace l6470emu::preload {
namespace {

DeviceBoard* g_board = nullptr;
std::string* g_report_path = nullptr;  // never freed: read at exit
Tick g_timeout = kNever;
std::atomic<bool> g_reported{false};
std::atomic<bool> g_devices{false};
std::string* g_waits_dir = nullptr;  // never freed
bool g_waits_published = false;      // (under the scheduler's lock)

void at_exit() { end_run(RunEnd::exit, ""); }

[[noreturn]] void refuse(const std::string& line) {
  const std::string text = line + "\n";
  raw_write_all(2, text.data(), text.size());
  _exit(kRunUsage);
}

}  // namespace

void start_run(DeviceBoard& board) {
  Guard guard;
  const char* report = std::getenv(kRunReportEnv);
  const char* scenario = std::getenv(kRunScenarioEnv);
  const char* timeout = std::getenv(kRunTimeoutEnv);
  if (!(report && *report) && !(scenario && *scenario) && !(timeout && *timeout)) return;
  g_board = &board;
  if (report && *report) g_report_path = new std::string(report);
  if (report && *report) {
    const std::string waits = run_waits_directory(report);
    if (real::access(waits.c_str(), W_OK) == 0) g_waits_dir = new std::string(waits);
  }
  if (timeout && *timeout) {
    char* end = nullptr;
    const unsigned long long t = std::strtoull(timeout, &end, 10);
    if (!end || *end || t == 0) refuse(std::string("l6470emu: ") + kRunTimeoutEnv + " is not a number of ticks");
    g_timeout = static_cast<Tick>(t);
  }
  if (scenario && *scenario) {
    std::ifstream in(scenario, std::ios::binary);
    if (!in) refuse(std::string("l6470emu: the run's scenario ") + scenario + " cannot be read");
    std::ostringstream text;
    text << in.rdbuf();
    std::string error;
    const auto s = deserialize_scenario(text.str(), error);
    if (!s) refuse("l6470emu: " + std::string(scenario) + ": " + error);
    try {
      board.set_scenario(*s);
    } catch (const std::exception& e) {
      refuse(std::string("l6470emu: scenario ") + e.what());
    }
  }
  start_fork_server(board);  // `l6470emu campaign`'s snapshots (its wait for the reruns runs after at_exit)
  std::atexit(at_exit);
}

bool in_run() { return g_board != nullptr; }

bool run_reads_report() { return g_board != nullptr && g_report_path != nullptr; }

Tick run_next_tick() {
  if (!g_board) return kNever;
  return g_board->scenario_next_tick();
}

Tick run_time_limit() { return g_board ? g_timeout : kNever; }

void run_time_reached(Tick now) {
  if (!g_board || now < g_timeout) return;
  end_run(RunEnd::timeout, "the simulated time limit " + seconds_text(g_timeout) + " was reached");
  for (std::size_t c = 0; c < g_board->chain_count(); ++c) g_board->stop_recording(c);
  finish_coverage();
  for (FILE* f : {stdout, stderr})
    if (ftrylockfile(f) == 0) {
      fflush_unlocked(f);
      funlockfile(f);
    }
  _exit(kTimeoutExitStatus);
}

void run_device_opened() { g_devices.store(true, std::memory_order_relaxed); }

void end_run(RunEnd cause, std::string_view detail) {
  if (!g_board || g_reported.exchange(true)) return;
  Guard guard;
  RunReport r;
  r.pid = getpid();
  r.end = cause;
  r.devices = g_devices.load(std::memory_order_relaxed);
  try {
    r.scenario = g_board->finish_scenario(r.outcome);
    r.tick = g_board->time().now();
    r.detail = detail_lines(detail);
  } catch (...) {
  }
  if (!g_report_path) return;
  const std::string text = format_run_report(r);
  // One write with O_APPEND: the blocks of several processes do not interleave.
  const int fd = real::open(g_report_path->c_str(), O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0) {
    log_line("the run report " + *g_report_path + " cannot be written");
    return;
  }
  raw_write_all(fd, text.data(), text.size());
  real::close(fd);
}

bool run_publishes_waits() { return g_board != nullptr && g_waits_dir != nullptr; }

void run_publish_waits(const std::string& text) {
  if (!run_publishes_waits()) return;
  const std::string pid = std::to_string(getpid());
  const std::string file = *g_waits_dir + "/" + pid, temp = *g_waits_dir + "/." + pid;
  const int fd = real::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) return;
  const bool written = raw_write_all(fd, text.data(), text.size());
  real::close(fd);
  // Whole or not at all: run never reads half a file.
  if (written && std::rename(temp.c_str(), file.c_str()) == 0)
    g_waits_published = true;
  else
    std::remove(temp.c_str());
}

void run_withdraw_waits() {
  if (!g_waits_published || !g_waits_dir) return;
  g_waits_published = false;
  const std::string file = *g_waits_dir + "/" + std::to_string(getpid());
  std::remove(file.c_str());
}

void run_after_fork_child() {
  g_waits_published = false;  // (the parent's file, not this process's)
  g_reported.store(false);
  g_devices.store(false);
  fork_server_after_fork_child();
}

bool run_devices_used() { return g_devices.load(std::memory_order_relaxed); }

void run_continue_as_rerun(const std::string& report_path) {
  g_report_path = new std::string(report_path);  // (the parent's stays: never freed)
  g_reported.store(false);
}

void leave_run() {
  Guard guard;
  g_board = nullptr;  // no report at exit, no time limit: the program's own board has them
  fork_server_leave();  // nor a campaign's snapshots (they are the preload board's)
}

}  // namespace l6470emu::preload

extern "C" __attribute__((visibility("default"))) long l6470emu_preload_leave_run(void) {
  l6470emu::preload::leave_run();
  return static_cast<long>(getpid());
}
