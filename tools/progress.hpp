// A progress bar for long work on the command line (replaying, decoding or converting a
// large trace): drawn on standard error when it is a terminal, silent otherwise (a pipe, a
// file, a test), so logs and scripts never see it. Formatting only; no work of its own.
#pragma once

#include <chrono>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <string_view>

#include "spi/trace.hpp"

namespace l6470emu {

/// One line of progress, `width` characters at most: "replaying run.trace [#####-----]  50%
/// 12.0 of 24.0 MB". `unit` names what done/total count: "bytes" (shown in kB/MB/GB) or
/// anything else (shown as numbers: "events"). Without a total: what was done, no bar.
std::string format_progress(std::string_view label, std::uint64_t done, std::uint64_t total, std::string_view unit,
                            std::size_t width = 80);
/// format_progress() with how many frames went by so far ("..., 12.3 M frames"): a trace's
/// `repeat` line stands for many frames on a few bytes, so the bytes alone would stand still.
std::string format_progress(std::string_view label, std::uint64_t done, std::uint64_t total, std::string_view unit,
                            std::size_t width, std::uint64_t frames);

/// Draws format_progress() lines over each other on `err` ('\r'), at most every 200 ms, and
/// clears the line when done. Does nothing at all when not enabled.
class ProgressBar {
 public:
  /// A bar on standard error, enabled only when it is a terminal.
  static ProgressBar on_stderr(std::string label);
  ProgressBar(std::ostream& err, bool enabled, std::string label);
  /// Clears the line (finish()).
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;
  ProgressBar(ProgressBar&&) = default;

  bool enabled() const { return enabled_; }
  /// Redraws when 200 ms passed since the last drawing.
  void update(std::uint64_t done, std::uint64_t total, std::string_view unit = "bytes");
  /// The same, saying how many frames went by (format_progress with frames).
  void update_frames(std::uint64_t done, std::uint64_t total, std::string_view unit, std::uint64_t frames);
  /// Takes the bar off the screen until the next drawing (before printing other lines).
  void clear();
  /// Clears the line; later updates draw nothing.
  void finish();

 private:
  std::ostream* err_;
  bool enabled_;
  std::string label_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point last_{};
};

/// A TraceReader that passes events through and moves a progress bar (every few thousand
/// events, from the reader's own progress() and the frames it counts).
class ProgressTraceReader final : public TraceReader {
 public:
  ProgressTraceReader(TraceReader& in, ProgressBar& bar) : in_(in), bar_(bar) {}
  const TraceHeader& header() const override { return in_.header(); }
  bool next(TraceEvent& e) override;
  ReadProgress progress() const override { return in_.progress(); }

 private:
  TraceReader& in_;
  ProgressBar& bar_;
  std::uint32_t count_ = 0;
  std::uint64_t frames_ = 0;
};

}  // namespace l6470emu
