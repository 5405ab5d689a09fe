// VCD export of a trace run through an emulated chain: the SPI wires bit by bit (mode 3)
// plus, per chip, BUSY and FLAG as the emulator drives them, SW, STCK and STBY as the trace
// drives them, ABS_POS, and the phase drive's COIL_A and COIL_B (daisychain/phase_drive.hpp, in
// tenths of a percent of full scale) as values. Levels between events are sampled, not exact.
#pragma once

#include <iosfwd>

#include "core/tick.hpp"
#include "daisychain/chain.hpp"
#include "spi/export_vcd.hpp"
#include "spi/trace.hpp"

namespace l6470emu {

/// Choices for export_emulated_vcd.
struct EmulatedVcdOptions {
  unsigned timescale_ns = 10;               ///< VCD time unit (1, 10 or 100 ns)
  Tick sample_ticks = ticks_from_us(10);    ///< while a chip moves, look at it this often
};

/// Writes a trace, replayed through `chain` (fresh), as VCD to `out`. Throws TraceError
/// for events naming chips outside the chain. Streams: it reads two passes side by side (the
/// events, the next frame's time) and writes as it goes, so its memory does not grow with the
/// trace (its output does, with the time the chips move: options.sample_ticks).
void export_emulated_vcd(const TracePasses& passes, Chain& chain, std::ostream& out,
                         const EmulatedVcdOptions& options = {});
/// The same for a trace in memory.
void export_emulated_vcd(const Trace& trace, Chain& chain, std::ostream& out, const EmulatedVcdOptions& options = {});

}  // namespace l6470emu
