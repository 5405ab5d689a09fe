// The first point where a trace and the emulator running it part, for the tools that show the
// emulator's view of a trace (decode, the motion series behind plot) so that what they show
// after it is never taken for the capture. Counts and the first one only; replay.hpp makes the
// full reports.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "core/chip.hpp"
#include "daisychain/chip_numbering.hpp"
#include "spi/trace.hpp"

namespace l6470emu {

/// The level of `chip`'s pin that an observation (TraceEvent::is_observation: BUSY, FLAG, or
/// SW as the axis drove it) is compared with.
bool observed_level(const Chip& chip, TracePin pin);

/// Where a trace and the emulator first disagree.
struct FirstDivergence {
  /// chip when no chip is to blame (MISO bytes past the chain's length: MOSI coming back).
  static constexpr std::size_t kNoChip = static_cast<std::size_t>(-1);
  bool found = false;
  std::uint64_t frame = 0;       ///< 1-based frame number (for a pin: the last frame before it)
  std::uint64_t line = 0;        ///< line of the trace file (0 = none)
  std::uint64_t repetition = 0;  ///< repetition of a native `repeat` line (0 = none)
  Tick tick = 0;                 ///< when (a frame's CS falling edge, a pin observation's time)
  double seconds = 0;            ///< the time as shown: the capture's own when it has one
  std::size_t chip = kNoChip;    ///< chain index of the chip that differed (0 drives MISO)
  std::size_t number = kNoChip;  ///< the same chip as the user numbers it
  std::string what;              ///< "MISO byte 1 expected 0x7E, emulated 0x7C", "BUSY expected high, emulated low"
  std::string summary;           ///< one line: "spi.txt:23: frame 12 at t=1.234567 s: chip 0: MISO byte ..."
};

/// Compares what a trace captured with what the emulator gives while the trace runs through it.
class DivergenceWatch {
 public:
  DivergenceWatch(std::string name, ChipNumbering numbering);

  /// A frame's bytes were clocked: its captured MISO (where known) against `emulated`.
  void frame(const TraceEvent& e, std::span<const std::uint8_t> emulated);
  /// A BUSY, FLAG or SW (axis) observation against the level the emulated chip has at its tick.
  void observation(const TraceEvent& e, bool emulated);

  const FirstDivergence& first() const { return first_; }
  bool diverged() const { return first_.found; }
  std::uint64_t frames_diverged() const { return frames_diverged_; }
  std::uint64_t pins_diverged() const { return pins_diverged_; }
  /// "DIVERGED in 3 frames and 1 pin level" (or "matched").
  std::string counts() const;

 private:
  void found(const TraceEvent& e, std::size_t chip, std::string what);

  std::string name_;
  ChipNumbering numbering_;
  FirstDivergence first_;
  std::uint64_t frames_ = 0;
  std::uint64_t frames_diverged_ = 0;
  std::uint64_t pins_diverged_ = 0;
};

}  // namespace l6470emu
