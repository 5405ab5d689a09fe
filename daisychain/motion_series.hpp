// What the motors did over a trace, as time series for plotting: a trace replayed through
// an emulated chain, each chosen chip's ABS_POS, SPEED, MOT_STATUS, BUSY, FLAG, SW and HiZ
// sampled at the ticks where they matter, and the commands each chip decoded. Integers in
// the datasheet's units only; conversions to step/s and seconds are the reader's business.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/tick.hpp"
#include "core/variant.hpp"
#include "daisychain/chain.hpp"
#include "daisychain/chip_numbering.hpp"
#include "daisychain/divergence.hpp"
#include "spi/trace.hpp"

namespace l6470emu {

/// One chip's state at one tick, exactly as the emulated chip has it then.
struct MotionSample {
  Tick tick = 0;
  std::int32_t abs_pos = 0;    ///< ABS_POS, microsteps of the STEP_SEL in force
  /// SPEED register (2^-28 full step/tick), negative while turning in reverse. A chip without
  /// one (the L6474, moved by STCK pulses) has its step rate in the same units instead: ABS_POS's
  /// change over the last window of at least 10 ms (or the grid step, when longer), held until
  /// the next window closes.
  std::int32_t speed = 0;
  std::uint8_t mot_status = 0; ///< MOT_STATUS: 0 stopped, 1 accelerating, 2 decelerating, 3 constant speed
  bool busy = true;            ///< BUSY pin level (false = pulled low: a command is running)
  bool flag = true;            ///< FLAG pin level (false = pulled low: an enabled alarm)
  bool sw = true;              ///< SW pin level (false = switch closed)
  bool hiz = true;             ///< bridges in high impedance
};

/// A command a chip decoded (NOP, GetParam and GetStatus left out): when its frame ended
/// (CS rising edge, when it acts), its name and its argument in words.
struct CommandMark {
  Tick tick = 0;
  std::uint8_t opcode = 0;
  std::string name;  ///< "Move(FWD)", "SetParam(ACC)", "SoftStop"
  std::string text;  ///< "Move(FWD, 3200 microsteps)"
};

/// One chip's series.
struct ChipMotion {
  std::size_t chip = 0;               ///< chain index (0 drives MISO)
  std::size_t number = 0;             ///< the chip's number as MotionOptions::number_from counts
  std::string variant;                ///< "L6470"
  unsigned microsteps_per_step = 128; ///< of the STEP_SEL in force at the window's end
  std::vector<MotionSample> samples;  ///< in time order, at most MotionOptions::max_points
  std::vector<CommandMark> commands;  ///< in time order, inside the window
  std::uint64_t commands_dropped = 0; ///< commands in the window beyond max_commands
};

/// How far a pass over a trace has come, for a progress bar: called with the reader's
/// progress() (bytes of the file, or events) when the pass begins, every few thousand events,
/// and once when it ends, then with done == total (total = done when the reader cannot say).
/// `done` never goes back within a pass. The pass's own work; the caller limits the rate it
/// draws at.
using PassProgress = std::function<void(const ReadProgress&)>;

/// The most samples a chip's series may ask for (MotionOptions::max_points): a picture has a
/// few thousand columns, and memory and time grow with the number.
inline constexpr std::size_t kMaxMotionPoints = 100'000;

/// Choices for sample_motion.
struct MotionOptions {
  std::vector<std::size_t> chips;  ///< chips to sample, numbered as number_from says (empty = all)
  NumberFrom number_from = NumberFrom::miso;  ///< how `chips` and ChipMotion::number count
  Tick from = 0;                   ///< the window: samples and commands from this tick ...
  Tick to = kNever;                ///< ... up to this one (kNever = the trace's end plus `tail`)
  /// Past the trace's last event, motion still going is followed for at most this long.
  Tick tail = kTicksPerSecond;
  /// Most samples per chip: a long run is sampled on a coarser grid and then thinned (each
  /// time slice keeps its first and last sample and those with the extremes of ABS_POS and
  /// SPEED and the first change of each pin), so the picture keeps its shape. At least 64
  /// (a smaller number is taken as 64), at most kMaxMotionPoints (more is refused).
  std::size_t max_points = 4000;
  std::size_t max_commands = 2000;  ///< most command marks per chip
  PassProgress progress;            ///< told how far the replay has come (empty: nobody asks)
};

/// The series of a trace's window.
struct MotionSeries {
  Tick from = 0, to = 0;          ///< the window actually sampled
  Tick trace_end = 0;             ///< the last event's tick (frame: its CS rising edge)
  std::vector<ChipMotion> chips;  ///< in the order asked for
  /// Where the emulator first gave MISO bytes or a BUSY/FLAG level other than the trace's, up
  /// to the window's end: from there on the series are the emulator's model, not the capture.
  FirstDivergence divergence;
  std::uint64_t frames_diverged = 0;  ///< frames read with a captured MISO byte the emulator gives differently
  std::uint64_t pins_diverged = 0;    ///< BUSY/FLAG observations read that the emulator does not reproduce
};

/// The last tick of a trace: the latest event's tick (a frame's CS rising edge). `progress`
/// (if any) is told how far the reading has come.
Tick trace_end_tick(TraceReader& in, const PassProgress& progress = {});

/// Replays `in` through `chain` (fresh, as the capture began) and samples the chosen chips.
/// Samples are taken at the window's edges, after every trace event inside the window that
/// touches the chip, at every tick where the motion engine's rule changes (the ends of
/// acceleration, constant speed and deceleration: MOT_STATUS and BUSY edges to the tick),
/// and on a regular grid of about max_points / 4 ticks across the window while a chip moves.
/// `trace_end` is trace_end_tick() of the same trace (needed for an open window).
/// Throws TraceError for malformed input and events naming chips outside the chain, and
/// std::invalid_argument for a chip outside the chain, an empty window or more than
/// kMaxMotionPoints points.
MotionSeries sample_motion(TraceReader& in, Chain& chain, Tick trace_end, const MotionOptions& options = {});

}  // namespace l6470emu
