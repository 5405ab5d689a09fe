// The driver sanitizer: watches a host on a chain's bus (wire settings, CS timing, frames,
// messages) and hears the chips' diagnostics, and names each broken rule of the chip's
// interface (board/check_rules.hpp) with the chip in the user's numbering, the frame and byte,
// and where the datasheet states it. check=warn logs; check=error keeps the first as the run's
// failure, which the front ends the run with. It changes nothing the chips do.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "board/check_rules.hpp"
#include "core/diagnostics.hpp"
#include "core/tick.hpp"
#include "daisychain/chain.hpp"
#include "daisychain/chip_numbering.hpp"
#include "spi/wire.hpp"

namespace l6470emu {

/// Where a board's diagnostics go: one line per call, without "l6470emu: " or a newline.
using LineSink = std::function<void(std::string_view)>;

/// One broken rule, where it happened.
struct Violation {
  Rule rule = Rule::SPI_MODE;
  std::string chain;                  ///< the chain's name ("spidev0.0")
  std::string chip;                   ///< "chip 1" in the user's numbering, "every chip", ... ("" = none)
  std::string chip_key;               ///< for counting repeats: the chip's chain index, or ""
  std::uint64_t frame = 0;            ///< CS frame on the chain, counted from 1 (0 = before any)
  std::optional<std::uint64_t> byte;  ///< byte of that frame, counted from 0
  Tick tick = 0;                      ///< when (the board's clock)
  std::string what;                   ///< what happened and what the chip makes of it
};

/// "spidev0.0: chip 1: WRONG_CMD: byte 0xEB: reserved opcode (frame 3, byte 0)".
std::string violation_line(const Violation& v);
/// How a check=error failure reaches the program: it ends the run (a preloaded or firmware
/// program), or it is raised as an exception (Python's SanitizerError) that the test may catch.
enum class FailureEnd : std::uint8_t { run_ends, raised };

/// The report of a failure under check=error: the rule, the chain and chip, the frame and byte,
/// what happened, the datasheet's place, what happens now (`end`), and how to allow the rule.
/// Several lines.
std::string violation_report(const Violation& v, FailureEnd end = FailureEnd::run_ends);

/// A board's check settings and its one failure: where every ChainChecker reports.
class Sanitizer {
 public:
  /// Log lines go to `log` (may be empty).
  explicit Sanitizer(CheckConfig config = {}, LineSink log = {});

  const CheckConfig& config() const { return config_; }
  void set_config(const CheckConfig& config) { config_ = config; }
  /// Where the log lines go from now on (a front that also turns them into warnings of its own).
  void set_log(LineSink log) { log_ = std::move(log); }
  CheckLevel level() const { return config_.level; }

  /// A broken rule: dropped when the level is off or the rule allowed; under warn a log line
  /// (each rule shown ten times per chain and chip, then counted at every power of ten); under
  /// error the first one is kept as the failure, later ones dropped until it is taken.
  void report(const Violation& v);
  /// Whether a failure is waiting to be taken.
  bool failed() const { return failure_.has_value(); }
  /// The failure's report (violation_report), taken: the next violation can be reported.
  std::optional<std::string> take_failure(FailureEnd end = FailureEnd::run_ends);
  /// The failure, without taking it.
  const std::optional<Violation>& failure() const { return failure_; }
  /// Broken rules reported so far at warn or error (allowed ones and check=off: none), and the
  /// first of them (a scenario's `expect: {sanitizer: clean}`).
  std::uint64_t broken() const { return broken_; }
  const std::optional<Violation>& first_broken() const { return first_broken_; }
  /// Who hears of every broken rule counted by broken() (interface coverage); empty: nobody.
  void set_broken_sink(std::function<void(const Violation&)> sink) { broken_sink_ = std::move(sink); }

 private:
  CheckConfig config_;
  LineSink log_;
  std::optional<Violation> failure_;
  std::uint64_t broken_ = 0;
  std::optional<Violation> first_broken_;
  std::function<void(const Violation&)> broken_sink_;
  std::unordered_map<std::string, std::uint64_t> seen_;  // chain/chip/rule -> times reported
};

/// The checks of one chain: the bus calls it around every CS edge and exchange (ChainBus), the
/// board hands it the chips' diagnostics. Cheap while nothing is broken: O(1) per exchange and
/// per frame, O(chips) per message of several frames.
class ChainChecker {
 public:
  /// Checks `chain` (named `name`, chips numbered as `numbering` says) for `sanitizer`; both
  /// must outlive the checker.
  ChainChecker(Sanitizer& sanitizer, const Chain& chain, std::string name, NumberFrom numbering = NumberFrom::miso);

  /// A bus use begins (a message): `wire` is how the host drives the bus.
  void begin_use(const WireSettings& wire) {
    frames_in_use_ = 0;
    if (wire.cs_active_high != reported_cs_high_ && on()) check_cs_polarity(wire);
  }
  /// The use ends: a message of several frames that leaves some chips mid-command (COMMAND_SPLIT).
  void end_use() {
    if (frames_in_use_ >= 2 && on()) check_split();
  }
  /// CS fell at `tick` (the chain is selected); `timed`: the CS edges' times are the host's
  /// (t_disCS is checked).
  void selected(Tick tick, bool timed = true) {
    ++frame_;
    frame_bytes_ = 0;
    in_frame_ = true;
    cs_fall_ = tick;
    keep_mosi_ = false;
    if (!on()) return;
    if ((timed && last_frame_had_bytes_ && tick - last_deselect_ < kDeselectMinTicks) || chain_.standby_in_frame())
      selected_checks(tick, timed);
  }
  /// `tx` is about to be clocked with `wire` (the clocks ended at `tick`, as run_message charges them).
  void clocked(std::span<const std::uint8_t> tx, const WireSettings& wire, Tick tick) {
    if (!in_frame_ || tx.empty()) return;
    // The usual byte: settings as checked before, not the frame's first, no chip in standby.
    if (on() && ((frame_bytes_ == 0 && wire.cs_setup_timed) || keep_mosi_ || !(wire == checked_)))
      clocked_checks(tx, wire, tick);
    frame_bytes_ += tx.size();
  }
  /// CS is about to rise: the chips are about to decode their registers.
  void deselecting() {
    in_decode_ = true;
    if (!on() || frame_bytes_ == 0) return;
    if (frame_bytes_ != chain_.size() || keep_mosi_) deselecting_checks();
    // What each chip is about to decode, against what it holds (check_decode): most chips have
    // neither an answer pending nor a last argument byte coming, two loads each.
    chain_.for_each_register([this](std::size_t k, const Chip& chip, std::uint8_t byte) {
      if (chip.answer_bytes_pending() != 0 || chip.arguments_missing() == 1) check_decode(k, chip, byte);
    });
  }
  /// CS rose at `tick` (the chips decoded).
  void deselected(Tick tick) {
    in_decode_ = false;
    in_frame_ = false;
    last_frame_had_bytes_ = frame_bytes_ > 0;
    last_deselect_ = tick;
    if (frame_bytes_ > 0) ++frames_in_use_;
  }
  /// A diagnostic of chip `chip` (chain index).
  void chip_diagnostic(std::size_t chip, const Diagnostic& d);

  // ---- SPI at the pins (Board::drive_spi_clock): the edges a controller's bytes carry implicitly ----
  /// The frame's first CK edge came at `tick` (CS_SETUP_TIME when sooner than t_setCS after CS fell).
  void first_clock_edge(Tick tick) {
    if (on() && in_frame_ && tick < cs_fall_ + kCsSetupMinTicks) report_early_clock(tick);
  }
  /// SPI_PINS: the frame under way broke the pins' rules (`what` says how); `byte`: where.
  void spi_pins(std::optional<std::uint64_t> byte, std::string what);

  /// CS frames seen so far.
  std::uint64_t frames() const { return frame_; }

 private:
  Violation make(Rule rule, std::optional<std::size_t> chip, std::optional<std::uint64_t> byte, std::string what) const;
  bool on() const { return sanitizer_.level() != CheckLevel::off; }
  void clocked_checks(std::span<const std::uint8_t> tx, const WireSettings& wire, Tick tick);
  void report_early_clock(Tick first_edge);
  void check_cs_polarity(const WireSettings& wire);
  void check_split();
  void selected_checks(Tick tick, bool timed);
  void deselecting_checks();
  void check_settings(const WireSettings& wire);
  void check_decode(std::size_t chip, const Chip& c, std::uint8_t byte);
  std::optional<std::uint64_t> decoded_at(std::size_t frame_len, std::size_t chip) const;
  void check_unused_bits(std::size_t chip, const Chip& c, std::uint32_t arg, std::optional<std::uint64_t> byte);
  void check_reserved_bits(std::size_t chip, const Chip& c, std::uint32_t arg, std::optional<std::uint64_t> byte);

  Sanitizer& sanitizer_;
  const Chain& chain_;
  std::string name_;
  ChipNumbering numbering_;
  // The frame being clocked or decoded.
  std::uint64_t frame_ = 0;
  std::uint64_t frame_bytes_ = 0;
  bool in_frame_ = false, in_decode_ = false;
  Tick cs_fall_ = 0;
  bool timed_settings_ = false;  // the current frame's first clocks are timed (cs_setup_timed)
  // Between frames.
  bool last_frame_had_bytes_ = false;
  Tick last_deselect_ = 0;
  // The message.
  std::uint64_t frames_in_use_ = 0;
  // Settings already reported (once per distinct problem): the last bad value of each.
  WireSettings checked_{0, false, false, 255, 0, false};  // no host has 255-bit words: the first settings are checked
  int reported_mode_ = -1, reported_bits_ = -1;
  bool reported_lsb_ = false, reported_cs_high_ = false;
  std::uint32_t reported_speed_ = 0;
  // A frame with a chip in standby keeps its MOSI bytes (to see what the standby chips missed).
  bool keep_mosi_ = false;
  std::vector<std::uint8_t> mosi_;
};

}  // namespace l6470emu
