// Collects interface coverage (board/coverage.hpp) while a run goes on: the board, or a front
// holding a bare chain (Python's Chain), calls it with what the chips decode and refuse, what
// the host reads, the faults and pin changes it applies, and a look at every chip's STATUS after
// each step of the run. It changes nothing the chips do; it only takes note.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "board/check_rules.hpp"
#include "board/coverage.hpp"
#include "board/pins.hpp"
#include "core/chip.hpp"
#include "daisychain/chain.hpp"
#include "daisychain/chip_numbering.hpp"
#include "spi/trace.hpp"

namespace l6470emu {

/// The points one run has hit, chain by chain and chip by chip (chain indices: 0 drives MISO).
class CoverageCollector {
 public:
  /// Watches the next chain (chains are numbered in the order they are added): its chips and
  /// how users number them (the chain positions' names).
  void add_chain(const Chain& chain, NumberFrom numbering = NumberFrom::miso);
  std::size_t chain_count() const { return chains_.size(); }

  /// Chip `chip` decoded `op` with argument `arg`, about to run it (Chip::CommandSink).
  void command(std::size_t chain, std::size_t chip, const Chip& c, const Opcode& op, std::uint32_t arg);
  /// Chip `chip` noticed a host mistake (Chip's DiagnosticSink): a refusal or a wrong command.
  void diagnostic(std::size_t chain, std::size_t chip, const Diagnostic& d);
  /// After a step of the run (a frame, a pin, a fault, a wait): the flags every chip shows now.
  /// Cheap when nothing but reads (GetStatus, GetParam: they raise no flag) reached the chips
  /// since the last look and less than kLookInterval ticks have passed: flags that rise with time
  /// alone (the motion's phases) are looked at that often, or at the next command, pin or fault.
  /// `force`: look whatever happened (the run's end).
  void look(std::size_t chain, const Chain& ch, bool force = false);
  /// How often time alone makes a look: 1 ms.
  static constexpr Tick kLookInterval = 4000;
  /// A backdoor event applied to chip `chip` (value as Board::inject_fault takes it).
  void event(std::size_t chain, std::size_t chip, TraceFault fault, std::uint8_t value);
  /// An input pin of chip `chip` was driven to `level` (SW, STBY_RST, STCK).
  void input(std::size_t chain, std::size_t chip, Pin pin, bool level);
  /// The host read output `pin` (BUSY, FLAG) of chip `chip` and got `level`.
  void output_read(std::size_t chain, std::size_t chip, const Chip& c, Pin pin, bool level);
  /// An edge event of output `pin` of chip `chip` was handed to the host.
  void output_edge(std::size_t chain, std::size_t chip, Pin pin, bool rising);
  /// The sanitizer found `rule` broken, on chip `chip` of the chain or (nothing) the whole chain.
  void rule_broken(std::size_t chain, std::optional<std::size_t> chip, Rule rule);

  /// What the run has met so far.
  CoverageData data() const;

 private:
  struct ChipState {
    const CoverageUniverse* universe = nullptr;
    std::string variant;
    std::string position;                 // chain_position_name
    std::vector<std::uint8_t> hit;        // by universe index
    bool addressed = false;               // decoded a command (its chain position is hit)
    std::vector<StatusFlagPoint> flags;   // of the chip's STATUS layout
    std::vector<int> raised_index, observed_index;
    int get_status_index = -1;
    std::int32_t last_raised_status = -1;    // the STATUS last looked at (nothing new in it)
    std::int32_t last_observed_status = -1;  // the STATUS last read by the host
    std::int8_t last_read[2] = {-1, -1};     // the host's last BUSY / FLAG reads (-1: none)
    bool sw_low = false, stby_low = false;
    // The command being run: a write or a motion command counts once no refusal follows it.
    Opcode pending{};
    bool has_pending = false;
    std::uint8_t pending_step_sel = 0;
    std::string_view pending_register;  // SetParam's register, in the table then in force
  };

  ChipState& chip(std::size_t chain, std::size_t chip);
  static void mark(ChipState& s, CoverageCategory c, std::string_view name);
  static void mark_index(ChipState& s, int index) {
    if (index >= 0) s.hit[static_cast<std::size_t>(index)] = 1;
  }
  static void settle(ChipState& s);  // the pending command was not refused
  static void saw_status(ChipState& s, std::uint16_t status, bool observed);

  std::vector<std::vector<ChipState>> chains_;
  struct ChainLook {
    bool looked = false;
    Tick at = 0;
    bool dirty = true;  // a command other than a read, a refusal, a pin or a fault since then
  };
  std::vector<ChainLook> looks_;
};

}  // namespace l6470emu
