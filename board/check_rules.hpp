// The driver sanitizer's rules: each rule a host can break that silicon would silently turn
// into wrong bits or a wrong motion, with a stable name (what check.allow= takes), what it is
// about and where the datasheet states it; the check levels; the exit status of a program that
// broke one under check=error. Names only; board/sanitizer.hpp does the checking.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace l6470emu {

/// How strictly a board checks its host: not at all, a log line per problem (rate-limited),
/// or the first problem ends the run with one report.
enum class CheckLevel : std::uint8_t { off, warn, error };

/// Exit status of a program under the preload that broke a rule under check=error (as
/// sanitizers have theirs: ASan exits 1 unless told, UBSan's halt_on_error too). Chosen clear
/// of the shell's 126-165 and of the usual 0-3.
inline constexpr int kSanitizerExitStatus = 86;

/// A rule of the chip's interface.
enum class Rule : std::uint8_t {
  SPI_MODE,            ///< SPI mode other than 3
  LSB_FIRST,           ///< bytes shifted least significant bit first
  CS_ACTIVE_HIGH,      ///< chip-select asserted high
  WORD_SIZE,           ///< words other than 8 bits
  SCK_SPEED,           ///< SCK above 5 MHz
  CS_DESELECT_TIME,    ///< CS high for less than t_disCS between frames
  CS_SETUP_TIME,       ///< first clock edge less than t_setCS after CS fell
  FRAME_LENGTH,        ///< a CS frame whose length is not a multiple of the chain's
  FRAME_PASS_THROUGH,  ///< a CS frame of several chain lengths: the earlier bytes are never decoded
  COMMAND_SPLIT,       ///< a message ends while one chip still waits for argument bytes and another does not
  WRONG_CMD,           ///< a byte that is no command, or a register address the chip lacks
  NOTPERF_CMD,         ///< a command the chip refuses in its state
  READ_ONLY_WRITE,     ///< SetParam of a read-only register
  UNUSED_BITS,         ///< a value with bits its register or argument does not have
  ANSWER_LOST,         ///< a GetParam/GetStatus answer replaced before all its bytes were clocked out
  STANDBY_BYTE,        ///< a command byte sent to a chip held in standby
  RESERVED_BITS,       ///< SetParam setting a bit the datasheet reserves (to be written 0)
  SPI_PINS,            ///< SPI at the pins out of step: a CS frame with no clock, a frame ending inside a byte
  count
};

inline constexpr std::size_t kRuleCount = static_cast<std::size_t>(Rule::count);

/// What the docs and reports say about a rule.
struct RuleInfo {
  Rule rule;
  std::string_view name;       ///< stable name, as check.allow= takes it
  std::string_view about;      ///< one line: what the rule is
  std::string_view datasheet;  ///< where the datasheet states it (L6470 rev 3 numbering)
  /// CONFIRMED: the datasheet (or a public report of silicon) states the rule and what breaking
  /// it does; UNCONFIRMED: the limit is stated but what the chip then does, or the rule itself,
  /// is our reading. One line, the mark first.
  std::string_view mark;
};

/// Every rule, in Rule order.
const std::array<RuleInfo, kRuleCount>& rule_table();
/// The entry of `rule`.
const RuleInfo& rule_info(Rule rule);
/// The rule called `name` (exact, case-insensitive), or nothing.
std::optional<Rule> rule_named(std::string_view name);

/// A set of rules (check.allow=).
class RuleSet {
 public:
  bool contains(Rule r) const { return (bits_ >> static_cast<unsigned>(r)) & 1u; }
  void insert(Rule r) { bits_ |= std::uint32_t{1} << static_cast<unsigned>(r); }
  bool empty() const { return bits_ == 0; }
  friend bool operator==(const RuleSet&, const RuleSet&) = default;

 private:
  std::uint32_t bits_ = 0;
};

/// A board's check settings: the description's check= and check.allow= (or the environment's).
struct CheckConfig {
  CheckLevel level = CheckLevel::warn;
  RuleSet allowed;  ///< rules never reported
  friend bool operator==(const CheckConfig&, const CheckConfig&) = default;
};

/// "off", "warn", "error".
std::string_view to_string(CheckLevel level);
/// Parses a check level; on failure `error` says what is accepted (with a suggestion).
std::optional<CheckLevel> parse_check_level(std::string_view text, std::string& error);
/// Parses a comma-separated list of rule names; on failure `error` names the bad one, with a
/// suggestion and the known names.
std::optional<RuleSet> parse_rule_list(std::string_view text, std::string& error);
/// The rules of `set`, comma separated, in Rule order.
std::string rule_list(const RuleSet& set);
/// Every rule name, comma separated.
std::string all_rule_names();

}  // namespace l6470emu
