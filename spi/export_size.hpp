// How many bytes an export of a trace writes, counted from its events without writing them:
// what `convert` checks against its output limit before it writes anything. Not the exports
// themselves (trace_native.hpp, export_umockdev.hpp, export_vcd.hpp).
#pragma once

#include <cstdint>

#include "spi/trace.hpp"

namespace l6470emu {

/// The outputs whose size can be counted.
enum class ExportFormat : std::uint8_t {
  native,           ///< native text, repeated frames collapsed into `repeat` lines
  native_expanded,  ///< native text, one line per frame (`convert --expand`)
  umockdev_ioctl,   ///< umockdev .ioctl
  vcd,              ///< VCD, the SPI wires drawn bit by bit
};

/// Adds up, event by event, the bytes an export writes for a trace (uncompressed): exact for
/// the lines of expanded native text and umockdev (the header and `wire` lines left out); for
/// compact native text the lines outside `repeat` lines (a `repeat` line's frames cost it
/// almost nothing); for VCD a lower bound, the two clock edges of every bit at times of their
/// own (what a VCD adds for pins, and an emulated chain for its outputs and positions, on top).
/// Costs no memory however long the trace or its frames.
class ExportSizeCounter {
 public:
  /// `vcd_timescale_ns`: the VCD time unit (1, 10 or 100 ns), which sets how long its times are.
  explicit ExportSizeCounter(ExportFormat format, unsigned vcd_timescale_ns = 10);

  /// Counts one event (events come in the trace's order).
  void add(const TraceEvent& e);
  /// Bytes the export writes for the events counted so far (at least, for VCD).
  std::uint64_t bytes() const { return bytes_; }
  /// Frames counted, and their MOSI bytes.
  std::uint64_t frames() const { return frames_; }
  std::uint64_t frame_bytes() const { return frame_bytes_; }

 private:
  void add_vcd_frame(const TraceEvent& e);
  void add_bytes(std::uint64_t n);

  ExportFormat format_;
  std::uint64_t unit_ns_;
  std::uint64_t bytes_ = 0;
  std::uint64_t frames_ = 0;
  std::uint64_t frame_bytes_ = 0;
  std::uint64_t vcd_last_ns_ = 0;  // the earliest the VCD's last change can be, in ns
};

}  // namespace l6470emu
