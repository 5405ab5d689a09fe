// The preload's coverage file: enabled from L6470EMU_COVERAGE, merged at the process's end.
#include "linux/preload/coverage.hpp"

#include <atomic>
#include <cstdlib>

#include "board/coverage_file.hpp"
#include "linux/preload/state.hpp"

namespace l6470emu::preload {
namespace {

DeviceBoard* g_board = nullptr;
std::string* g_path = nullptr;  // never freed: read at exit
std::atomic<bool> g_done{false};

void at_exit() { finish_coverage(); }

}  // namespace

std::string check_coverage_environment() {
  const char* path = std::getenv(kCoverageEnv);
  if (!path) return "";
  if (const std::string why = check_coverage_output(path); !why.empty())
    return std::string("l6470emu: ") + kCoverageEnv + ": " + why;
  return "";
}

void start_coverage(DeviceBoard& board) {
  const char* path = std::getenv(kCoverageEnv);
  if (!path || !*path || g_board) return;
  Guard guard;
  g_path = new std::string(path);
  g_board = &board;
  board.enable_coverage();
  std::atexit(at_exit);
}

void finish_coverage() {
  if (!g_board || g_done.exchange(true)) return;
  Guard guard;
  // A thread still inside the board at exit keeps it: its last operation is not waited for.
  const auto data = g_board->coverage(true);
  if (!data) {
    log_line("coverage not written to " + *g_path + ": another thread held the board at exit");
    return;
  }
  if (const std::string error = merge_into_coverage_file(*g_path, *data); !error.empty())
    log_line("coverage not written: " + error);
}

void coverage_after_fork_child() { g_done.store(false); }

}  // namespace l6470emu::preload
