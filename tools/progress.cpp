// Progress bar: formatting, throttling and the terminal check.
#include "tools/progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <iostream>

namespace l6470emu {
namespace {

std::string amount(std::uint64_t n, std::string_view unit) {
  char buf[48];
  if (unit != "bytes") {
    std::snprintf(buf, sizeof buf, "%llu", static_cast<unsigned long long>(n));
    return buf;
  }
  if (n < 10'000) std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(n));
  else if (n < 10'000'000) std::snprintf(buf, sizeof buf, "%.1f kB", static_cast<double>(n) / 1e3);
  else if (n < 10'000'000'000ull) std::snprintf(buf, sizeof buf, "%.1f MB", static_cast<double>(n) / 1e6);
  else std::snprintf(buf, sizeof buf, "%.1f GB", static_cast<double>(n) / 1e9);
  return buf;
}

}  // namespace

std::string format_progress(std::string_view label, std::uint64_t done, std::uint64_t total, std::string_view unit,
                            std::size_t width) {
  return format_progress(label, done, total, unit, width, 0);
}

std::string format_progress(std::string_view label, std::uint64_t done, std::uint64_t total, std::string_view unit,
                            std::size_t width, std::uint64_t frames) {
  std::string tail;
  if (total == 0) {
    tail = " " + amount(done, unit) + (unit == "bytes" ? "" : " " + std::string(unit));
  } else {
    if (done > total) done = total;
    const unsigned percent = static_cast<unsigned>(done * 100 / total);
    char pc[16];
    std::snprintf(pc, sizeof pc, " %3u%% ", percent);
    tail = pc + amount(done, unit) + " of " + amount(total, unit) + (unit == "bytes" ? "" : " " + std::string(unit));
  }
  if (frames > 0) {
    char buf[48];
    if (frames < 10'000) std::snprintf(buf, sizeof buf, ", %llu frames", static_cast<unsigned long long>(frames));
    else if (frames < 10'000'000) std::snprintf(buf, sizeof buf, ", %.1f k frames", static_cast<double>(frames) / 1e3);
    else std::snprintf(buf, sizeof buf, ", %.1f M frames", static_cast<double>(frames) / 1e6);
    tail += buf;
  }
  // The label is cut (from the left: the end of a path says most) to leave room for a bar of 10.
  constexpr std::size_t kMinBar = 10;
  const std::size_t fixed = tail.size() + (total ? kMinBar + 3 : 0);
  std::string l(label);
  if (fixed < width && l.size() > width - fixed) l = "…" + l.substr(l.size() - (width - fixed - 1));
  if (fixed >= width) l.clear();
  if (total == 0) return l + tail;
  // The "…" is 3 bytes for 1 column.
  const std::size_t label_columns = l.size() - (l.rfind("…", 0) == 0 ? 2 : 0);
  const std::size_t bar = width > label_columns + tail.size() + 3 ? std::min<std::size_t>(40, width - label_columns - tail.size() - 3) : kMinBar;
  const std::size_t filled = static_cast<std::size_t>(done * bar / total);
  return l + " [" + std::string(filled, '#') + std::string(bar - filled, '-') + "]" + tail;
}

ProgressBar ProgressBar::on_stderr(std::string label) {
  return ProgressBar(std::cerr, isatty(STDERR_FILENO) == 1, std::move(label));
}

ProgressBar::ProgressBar(std::ostream& err, bool enabled, std::string label)
    : err_(&err), enabled_(enabled), label_(std::move(label)), last_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(std::uint64_t done, std::uint64_t total, std::string_view unit) {
  update_frames(done, total, unit, 0);
}

void ProgressBar::update_frames(std::uint64_t done, std::uint64_t total, std::string_view unit, std::uint64_t frames) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ < std::chrono::milliseconds(200)) return;
  last_ = now;
  // Clear to the end of the line after the text: a shorter line leaves nothing behind.
  *err_ << '\r' << format_progress(label_, done, total, unit, 80, frames) << "\x1b[K" << std::flush;
  drawn_ = true;
}

void ProgressBar::clear() {
  if (enabled_ && drawn_) *err_ << "\r\x1b[K" << std::flush;
  drawn_ = false;
}

void ProgressBar::finish() {
  clear();
  enabled_ = false;
}

bool ProgressTraceReader::next(TraceEvent& e) {
  if (++count_ == 4096) {
    count_ = 0;
    const ReadProgress p = in_.progress();
    bar_.update_frames(p.done, p.total, p.bytes ? "bytes" : "events", frames_);
  }
  if (!in_.next(e)) return false;
  if (e.kind == TraceEventKind::frame) ++frames_;
  return true;
}

}  // namespace l6470emu
