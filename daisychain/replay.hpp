// Replay: drives a trace's MOSI into an emulated chain with the captured timing and
// compares every captured MISO byte (and BUSY/FLAG observation) with the emulator's.
// On a divergence it reports the frame, time, what each chip was decoding, expected vs
// emulated bytes and the chip state. It does not fix or skip anything in the trace.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "daisychain/chain.hpp"
#include "daisychain/chip_numbering.hpp"
#include "spi/trace.hpp"

namespace l6470emu {

/// Choices for replay_trace.
struct ReplayOptions {
  bool keep_going = false;        ///< report every divergence instead of stopping at the first
  std::size_t max_reports = 100;  ///< with keep_going: full reports kept for this many (0 = all); all are counted
  bool compare_pins = true;       ///< check the trace's BUSY/FLAG observations
  NumberFrom number_from = NumberFrom::miso;  ///< how the reports number the chips
};

/// One point where the emulator and the capture disagree.
struct Divergence {
  std::uint64_t frame = 0;  ///< 1-based frame number (the last frame before a pin observation)
  std::uint64_t line = 0;   ///< line of the trace file
  Tick tick = 0;
  double source_time = 0;   ///< seconds shown (capture time when the trace has one)
  std::string summary;      ///< one line: "capture.csv:35: frame 17 at t=...: MISO byte 1 differs ..."
  std::string report;       ///< the full report, summary line first
};

/// What a replay did.
struct ReplayResult {
  std::uint64_t frames = 0;
  std::uint64_t bytes_compared = 0;  ///< captured MISO bytes checked
  std::uint64_t bytes_unknown = 0;   ///< MISO bytes the trace does not know (not checked)
  std::uint64_t pin_checks = 0;      ///< BUSY/FLAG observations checked
  std::uint64_t divergent_frames = 0;
  std::uint64_t pin_mismatches = 0;
  bool stopped_early = false;  ///< stopped at the first divergence (not keep_going)
  std::vector<Divergence> divergences;  ///< the first max_reports of them
  bool matched() const { return divergent_frames == 0 && pin_mismatches == 0; }
};

/// Replays `in` through `chain` (fresh, as when the capture began). `on_divergence`, when
/// given, sees each reported divergence as soon as it is found. Throws TraceError for
/// malformed input and events naming chips outside the chain. The reports do not say which
/// chip numbering they use: the caller says it once (describe_numbering).
ReplayResult replay_trace(TraceReader& in, Chain& chain, const ReplayOptions& options = {},
                          const std::function<void(const Divergence&)>& on_divergence = {});

}  // namespace l6470emu
