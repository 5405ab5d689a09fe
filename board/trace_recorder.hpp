// Recording one chain of the board into a native trace (docs/trace-format.md): a
// RecordingChain over the chain and a NativeTraceWriter on a recording output (a memory-mapped
// file, a gzip file: spi/recording_output.hpp), event by event, so a killed process leaves a
// complete file.
// Never throws after it is open: a write error stops the recording and is reported once.
// Knows nothing of spidev, gpio or file descriptors; the Board drives it.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "board/pins.hpp"
#include "daisychain/recording_chain.hpp"
#include "spi/trace.hpp"
#include "spi/trace_output.hpp"

namespace l6470emu {

/// A native trace being recorded from one chain. Single-threaded: its owner (the Board) serialises every call.
class ChainTraceRecorder {
 public:
  /// Opens the output of `path` with `open_output` (open_recording_output without a clock when
  /// empty: mapped when plain, gzip flushed by size) and writes the header: the chain, its board
  /// description `board` (`board` lines), and the BUSY/FLAG levels. Returns nullptr and sets
  /// `error` (one line) when that fails.
  static std::unique_ptr<ChainTraceRecorder> open(
      Chain& chain, const std::string& path, const std::string& board,
      const std::function<std::unique_ptr<TraceOutput>(const std::string&)>& open_output, std::string& error) noexcept;
  ~ChainTraceRecorder();
  ChainTraceRecorder(const ChainTraceRecorder&) = delete;
  ChainTraceRecorder& operator=(const ChainTraceRecorder&) = delete;

  /// What SPI goes through: the chain, recording every CS frame at its CS rising edge.
  SpiDevice& device() { return recording_; }
  /// An input pin (SW, STCK, STBY_RST) of chip `chip` changes: applied to the chip and recorded.
  void set_input(std::size_t chip, Pin pin, bool level);
  /// A backdoor event (fault on/off, thermal class, ADCIN code): applied to the chip and recorded.
  void fault(std::size_t chip, TraceFault fault, std::uint8_t value);
  /// The load on chip `chip`'s axis changes: applied to the chip and recorded.
  void set_axis_load(std::size_t chip, const LoadSpec& load);
  /// Records that time was moved on to the chain's tick (`ctl advance`).
  void mark_advance();
  /// The recording chain itself, for the rarer stimuli (an axis attached or removed, its stops
  /// or supply changed): applied to the chip and recorded. Write errors end up in error().
  RecordingChain& recording() { return recording_; }
  /// Records BUSY/FLAG levels that changed since they were last seen.
  void observe_outputs() { recording_.observe_outputs(); }
  /// The chain was changed behind the recorder's back: the next look sees it.
  void outputs_may_have_changed() { recording_.outputs_may_have_changed(); }
  /// Hands what the output holds to the OS if its flush policy's time has come.
  void flush_if_due();
  /// Stops without writing anything more (a forked child's copy).
  void abandon();

  const std::string& path() const { return path_; }
  std::uint64_t frames() const { return recording_.frames_recorded(); }
  /// The first write error ("" while all is well); events after it are dropped.
  const std::string& error() const { return *error_; }

 private:
  class Sink;
  ChainTraceRecorder(Chain& chain, std::unique_ptr<Sink> sink, std::string path, const std::string& board);

  std::unique_ptr<Sink> sink_;
  const std::string* error_;  // the sink's (read on every frame: no call into the sink)
  RecordingChain recording_;
  std::string path_;
};

/// Applies a backdoor event to chip `chip` of `chain` without recording it (what
/// ChainTraceRecorder::fault does when nothing records): the wire faults and POWER_CYCLE go
/// through the chain (Chain::arm_miso_flip, arm_lost_frame, power_cycle).
void apply_fault(Chain& chain, std::size_t chip, TraceFault fault, std::uint8_t value);
/// Applies a chip's own backdoor event (not a wire fault: those need the chain, and are
/// ignored here; POWER_CYCLE leaves a chain's shift register to the chain).
void apply_fault(Chip& chip, TraceFault fault, std::uint8_t value);

/// The trace file of chain `name` when a board with `chains` chains records to `path`: `path`
/// itself for one chain, else the chain's name inserted before the extension
/// ("run.trace" -> "run.spidev0.1.trace").
std::string trace_path_for_chain(const std::string& path, const std::string& name, std::size_t chains);

}  // namespace l6470emu
