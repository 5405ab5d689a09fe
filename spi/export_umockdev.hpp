// Export of a trace as a umockdev SPI .ioctl recording, replayable with
// `umockdev-run -i /dev/spidevB.C=FILE`. umockdev has no times, pins or faults:
// those become comments; frames whose MISO is not fully known are written without R.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string_view>

#include "spi/trace.hpp"

namespace l6470emu {

/// What an export wrote.
struct UmockdevExportStats {
  std::uint64_t frames = 0;               ///< transfers written
  std::uint64_t frames_without_miso = 0;  ///< written without "R" (MISO not fully known)
  std::uint64_t empty_frames = 0;         ///< CS pulses without bytes (comments only)
};

/// Writes `in` as a umockdev .ioctl file for `device`: one "TW" transfer (with its " R"
/// answer) per CS frame, everything else as '#' comments. Streams (one event in memory at a
/// time) and stops at the first write error: std::ios_base::failure once `out` has gone bad.
UmockdevExportStats export_umockdev_ioctl(TraceReader& in, std::ostream& out,
                                          std::string_view device = "/dev/spidev0.0");

}  // namespace l6470emu
