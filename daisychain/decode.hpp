// Explains a trace: a human-readable log per chip ("t=1.234567 s  chip 2  SetParam(ACC,
// 0x08A = 2008 step/s²)", "GetStatus → 0x7E03 [...]") with protocol diagnostics, built on a
// shadow chain (ProtocolTracker). It describes the captured bytes; it does not judge them
// against the emulator (replay.hpp does), beyond noting answers the emulator would give
// differently and marking, with a banner, where the emulator first parts from the trace.
#pragma once

#include <cstdint>
#include <iosfwd>

#include "daisychain/chain.hpp"
#include "daisychain/chip_numbering.hpp"
#include "daisychain/divergence.hpp"
#include "spi/trace.hpp"

namespace l6470emu {

/// Choices for decode_trace.
struct DecodeOptions {
  bool show_nops = false;        ///< also list NOP bytes
  std::size_t max_repeats = 10;  ///< each kind of diagnostic shown at most this often per chip (0 = all)
  int only_chip = -1;            ///< show only this chip's lines (and frame-level diagnostics), as numbered; -1 = all
  NumberFrom number_from = NumberFrom::miso;  ///< how the log numbers the chips (only_chip too)
};

/// Counts of what a decode found.
struct DecodeSummary {
  std::uint64_t frames = 0;
  std::uint64_t commands = 0;     ///< complete commands, NOPs excluded
  std::uint64_t answers = 0;      ///< GetParam/GetStatus answers
  std::uint64_t diagnostics = 0;  ///< protocol diagnostics, shown or not
  std::uint64_t suppressed = 0;   ///< diagnostics not shown (max_repeats)
  std::uint64_t answer_mismatches = 0;  ///< captured answers the emulator would give differently
  /// Where the emulator first gave MISO bytes or a BUSY/FLAG level other than the trace's (the
  /// log then shows a banner there: what follows is the emulator's model, not the capture).
  FirstDivergence divergence;
  std::uint64_t frames_diverged = 0;  ///< frames with a captured MISO byte the emulator gives differently
  std::uint64_t pins_diverged = 0;    ///< BUSY/FLAG observations the emulator does not reproduce
};

/// Writes the log of `in`, run through `chain` (fresh, as the capture began), to `out`.
/// Throws TraceError for malformed input and events naming chips outside the chain, and
/// std::invalid_argument for an only_chip outside the chain. The log has no header: the
/// caller says which numbering it uses (describe_numbering).
DecodeSummary decode_trace(TraceReader& in, Chain& chain, std::ostream& out, const DecodeOptions& options = {});

}  // namespace l6470emu
