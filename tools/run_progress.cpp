// run's progress line (tools/run_progress.hpp).
#include "tools/run_progress.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "board/scenario.hpp"

namespace l6470emu {

std::string format_run_progress(const RunProgress& p, double wall_seconds) {
  char wall[32];
  std::snprintf(wall, sizeof wall, "%.0f", wall_seconds);
  return "l6470emu run: " + seconds_text(p.tick) + " of board time, " + std::to_string(p.messages) + " SPI message" +
         (p.messages == 1 ? "" : "s") + " (" + wall + " s of wall time)";
}

std::unique_ptr<RunProgressLine> RunProgressLine::on_terminal() {
  if (!isatty(2)) return nullptr;
  const char* tmp = std::getenv("TMPDIR");
  std::string path = std::string(tmp && *tmp ? tmp : "/tmp") + "/l6470emu-progress-XXXXXX";
  const int fd = mkstemp(path.data());
  if (fd < 0) return nullptr;
  void* page = MAP_FAILED;
  if (ftruncate(fd, static_cast<off_t>(kRunProgressBytes)) == 0)
    page = mmap(nullptr, kRunProgressBytes, PROT_READ, MAP_SHARED, fd, 0);
  close(fd);
  if (page == MAP_FAILED) {
    unlink(path.c_str());
    return nullptr;
  }
  return std::unique_ptr<RunProgressLine>(new RunProgressLine(std::move(path), page));
}

RunProgressLine::RunProgressLine(std::string path, void* page) : path_(std::move(path)), page_(page) {}

RunProgressLine::~RunProgressLine() {
  finish();
  munmap(page_, kRunProgressBytes);
  unlink(path_.c_str());
}

std::string RunProgressLine::environment_entry() const { return std::string(kRunProgressEnv) + "=" + path_; }

RunProgress RunProgressLine::read() const {
  const auto* w = static_cast<const std::atomic<std::uint64_t>*>(page_);
  return RunProgress{w[0].load(std::memory_order_relaxed), w[1].load(std::memory_order_relaxed)};
}

void RunProgressLine::finish() {
  if (drawn_) std::cerr << "\r\033[K" << std::flush;
  drawn_ = false;
  finished_ = true;
}

void RunProgressLine::update() {
  if (finished_) return;
  using namespace std::chrono;
  const auto now = steady_clock::now();
  if (now - start_ < seconds(2) || now - last_ < milliseconds(500)) return;
  last_ = now;
  std::cerr << "\r\033[K" << format_run_progress(read(), duration<double>(now - start_).count()) << std::flush;
  drawn_ = true;
}

}  // namespace l6470emu
