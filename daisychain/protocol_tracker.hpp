// A shadow of a chain's SPI protocol: runs captured frames through the emulated chain
// and works out, chip by chip, which bytes made up which command, which MISO bytes
// were which answer, and what a real chip would have misread. It explains the bytes;
// whether the captured answers match the emulator is replay.hpp's business.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/commands.hpp"
#include "core/diagnostics.hpp"
#include "core/registers.hpp"
#include "core/variant.hpp"
#include "daisychain/chain.hpp"
#include "daisychain/chip_numbering.hpp"
#include "spi/trace.hpp"

namespace l6470emu {

/// What a chip was doing with the bytes, reported by ProtocolTracker.
struct ProtocolEvent {
  enum class Kind : std::uint8_t {
    command,     ///< a complete command was decoded (its opcode and every argument byte)
    answer,      ///< a GetParam/GetStatus answer: all its bytes came out on MISO, or it was cut short
    diagnostic,  ///< something a real chip would misread or refuse
  };
  /// What kind of diagnostic (for counting and filtering).
  enum class Issue : std::uint8_t {
    none,
    wrong_cmd,     ///< the chip set WRONG_CMD (unknown opcode, missing register, reserved)
    notperf_cmd,   ///< the chip refused a command (NOTPERF_CMD)
    chain_length,  ///< frame length differs from the chain length
    standby,       ///< a byte reached a chip held in standby
    answer_lost,   ///< answer bytes never reached MISO (short frame, replaced, reset)
  };
  static constexpr std::size_t kNoChip = std::numeric_limits<std::size_t>::max();

  Kind kind = Kind::command;
  Issue issue = Issue::none;
  std::size_t chip = kNoChip;   ///< kNoChip for frame-level diagnostics
  std::uint64_t frame = 0;      ///< 0-based frame number where the command was decoded
  Tick tick = 0;                ///< CS falling edge of that frame (when it began)
  double source_time = std::numeric_limits<double>::quiet_NaN();  ///< that frame's capture time
  std::uint64_t line = 0;       ///< that frame's line in the trace file
  std::uint64_t repetition = 0; ///< that frame's repetition of a native `repeat` line (0 = none)

  // command and answer
  std::uint8_t opcode = 0;
  Opcode op{};
  std::uint32_t arg = 0;                 ///< argument bytes, MSB first
  const RegisterInfo* reg = nullptr;     ///< SetParam/GetParam register (table in force at decode)
  const Variant* table = nullptr;        ///< the register table in force at decode
  const StatusLayout* layout = nullptr;  ///< the chip's STATUS layout

  // answer
  std::uint8_t answer_bytes = 0;     ///< bytes of the answer
  std::uint32_t value = 0;           ///< the answer as captured on MISO (emulated where not captured)
  std::uint32_t emulated = 0;        ///< the answer the emulated chip gave
  bool captured = false;             ///< every byte of `value` came from the capture
  bool complete = true;              ///< all bytes came out on MISO

  std::string text;  ///< diagnostic: what happened, in words
};

/// Runs frames through a chain and explains them per chip. Use begin_frame() and
/// end_frame() around each frame (between them the chips have their bytes but have not
/// decoded them: the moment a replay compares MISO), apply() for pin and fault events.
class ProtocolTracker {
 public:
  using Observer = std::function<void(const ProtocolEvent&)>;

  /// Tracks `chain` (it must outlive the tracker; its chips' diagnostic sinks are taken over).
  /// Without an observer no events are built (cheap: replay only asks describe_*). Texts
  /// (diagnostics, describe_*) number the chips as `numbering` says; ProtocolEvent::chip and
  /// the arguments of describe_* stay chain indices.
  explicit ProtocolTracker(Chain& chain, Observer observer = {}, NumberFrom numbering = NumberFrom::miso);
  /// Gives the chips their diagnostic sinks back (empty).
  ~ProtocolTracker();
  ProtocolTracker(const ProtocolTracker&) = delete;
  ProtocolTracker& operator=(const ProtocolTracker&) = delete;

  /// CS falls at frame.tick and the MOSI bytes are clocked as the frame's host did
  /// (TraceEvent::wire: a known wire through the chain's bit-level face, else SPI mode 3 byte by
  /// byte); `rx` (as long as frame.mosi) receives the emulated MISO, as that host reads it.
  /// Captured MISO bytes of `frame` are taken as the answers.
  /// `frame`'s bytes must stay valid until end_frame().
  void begin_frame(const TraceEvent& frame, std::span<std::uint8_t> rx);
  /// CS rises at frame.end(): the chips decode; events are reported.
  void end_frame();
  /// Applies a pin (inputs only; outputs are observations), fault, axis load or advance event to
  /// the chain, at its tick.
  void apply(const TraceEvent& e);
  /// The trace ended: reports answers still being shifted out as cut short.
  void finish();

  /// Between begin_frame() and end_frame(): where MISO byte `i` of this frame comes from,
  /// in words ("chip 0: byte 2 of 2 of GetStatus (decoded at t=...)").
  std::string describe_miso(std::size_t i) const;
  /// Between begin_frame() and end_frame(): what chip `k` is about to decode, in words.
  std::string describe_decode(std::size_t k) const;

  /// The time shown for the oldest answer still being shifted out (+infinity when none):
  /// its event comes later than events of frames after it.
  double pending_answer_seconds() const;

  /// Frames seen so far.
  std::uint64_t frames() const { return frame_no_; }
  Chain& chain() { return chain_; }
  /// How the texts number the chips.
  const ChipNumbering& numbering() const { return numbering_; }

 private:
  struct Answer {
    bool active = false;
    std::uint8_t opcode = 0;
    const RegisterInfo* reg = nullptr;  // nullptr = GetStatus
    const Variant* table = nullptr;
    std::uint8_t len = 0;
    std::uint8_t loaded = 0;  // index of the answer byte in the shift register now
    std::uint8_t seen = 0;    // bitmask of bytes that came out on MISO
    std::uint8_t known = 0;   // bitmask of those with a captured value
    std::uint32_t captured = 0, emulated = 0;
    std::uint64_t frame = 0;
    Tick tick = 0;
    double source_time = 0;
    std::uint64_t line = 0;
    std::uint64_t repetition = 0;
  };
  struct Collect {
    bool active = false;
    std::uint8_t opcode = 0;
    Opcode op{};
    const Variant* table = nullptr;
    std::uint8_t seen = 0;
    std::uint32_t arg = 0;
    std::uint64_t frame = 0;
  };
  struct ChipTrack {
    Answer answer;
    Collect collect;
    // Filled by begin_frame for end_frame.
    std::uint8_t byte = 0;
    bool enabled = true;  // takes part in the frame (Chain::hears_frame)
    bool lost = false;    // not in standby, yet misses the frame (a lost frame)
    bool was_collecting = false;
    const Variant* table = nullptr;
  };

  enum class AnswerEnd : std::uint8_t { shifted_out, replaced, trace_end };
  void finish_answer(std::size_t k, AnswerEnd why);
  void report(ProtocolEvent&& e);
  ProtocolEvent event_here(ProtocolEvent::Kind kind, std::size_t chip) const;
  std::string origin_of(std::size_t k) const;
  std::string chip_range(std::size_t first, std::size_t last) const;  // "chips 0..2" in user numbers
  std::string host_byte_for(std::size_t k) const;

  Chain& chain_;
  Observer observer_;
  ChipNumbering numbering_;
  std::vector<ChipTrack> chips_;
  struct PendingDiagnostic {
    std::size_t chip;
    Diagnostic d;
  };
  std::vector<PendingDiagnostic> diagnostics_;
  // The frame in progress.
  TraceEvent frame_;
  std::uint64_t frame_no_ = 0;
};

/// The MOSI byte of a frame of `frame_len` bytes that chip `chip` of a chain of `chain_len`
/// decodes at the CS rising edge (byte k of an N-byte frame goes to chip k; a longer frame's
/// first bytes pass through), or nothing when the chip decodes a byte left in the chain.
std::optional<std::size_t> mosi_byte_decoded_by(std::size_t frame_len, std::size_t chain_len, std::size_t chip);

/// Seconds to show for an event: the capture's own time when it has one, else the tick's.
double display_seconds(Tick tick, double source_time);

}  // namespace l6470emu
