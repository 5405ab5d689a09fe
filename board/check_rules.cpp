// The sanitizer's rule table (names, what each is about, where the datasheet states it) and
// the parsers of check= and check.allow=.
#include "board/check_rules.hpp"

#include <cctype>
#include <vector>

#include "core/near_miss.hpp"

namespace l6470emu {
namespace {

// Section, table and parameter names are those of the L6470 datasheet, Doc ID 16737 Rev 3.
constexpr std::array<RuleInfo, kRuleCount> kRules{{
    {Rule::SPI_MODE, "SPI_MODE", "the host clocks in an SPI mode other than 3 (CPOL=1, CPHA=1)",
     "§8 Serial interface: SDI sampled on CK rising edges, SDO latched on CK falling edges",
     "CONFIRMED for mode 0 (two public L6474 reports match the stale first bit); UNCONFIRMED for modes 1 and 2 (a hold-time race, our reading)"},
    {Rule::LSB_FIRST, "LSB_FIRST", "the host shifts bytes least significant bit first",
     "§8 Serial interface: bytes shifted in and out most significant bit first",
     "CONFIRMED (bit order stated)"},
    {Rule::CS_ACTIVE_HIGH, "CS_ACTIVE_HIGH", "the host asserts chip-select high",
     "§8 Serial interface: communication starts when CS is forced low; CS high deselects",
     "CONFIRMED (CS polarity stated)"},
    {Rule::WORD_SIZE, "WORD_SIZE", "the host clocks words other than 8 bits",
     "§8 Serial interface: an 8-bit interface; CS raised after each byte (each chain length of bytes)",
     "CONFIRMED (8-bit interface stated)"},
    {Rule::SCK_SPEED, "SCK_SPEED", "SCK is faster than 5 MHz",
     "Table 5 \"SPI\": f_CK,MAX = 5 MHz; t_hCK, t_lCK >= 75 ns",
     "CONFIRMED for the limit; UNCONFIRMED what a faster clock does (the model still shifts the bits)"},
    {Rule::CS_DESELECT_TIME, "CS_DESELECT_TIME", "CS stays high for less than t_disCS between frames",
     "Table 5 \"SPI\": t_disCS >= 800 ns; §8: the time to decode the byte and load the answer",
     "CONFIRMED for the limit; UNCONFIRMED that the answer is then not loaded (our reading of the timing)"},
    {Rule::CS_SETUP_TIME, "CS_SETUP_TIME", "the first clock edge comes less than t_setCS after CS fell",
     "Table 5 \"SPI\": t_setCS >= 350 ns",
     "CONFIRMED for the limit; UNCONFIRMED what an earlier edge does (the model still shifts the bits)"},
    {Rule::FRAME_LENGTH, "FRAME_LENGTH", "a CS frame's length is not a multiple of the chain's: bytes land in the wrong chips",
     "§8 Serial interface and Figure 18 (daisy chain): one byte per device between CS edges",
     "CONFIRMED (one byte per device per frame)"},
    {Rule::FRAME_PASS_THROUGH, "FRAME_PASS_THROUGH",
     "a CS frame of several chain lengths: only the last chain length of bytes is decoded",
     "§8 Serial interface: after each byte CS must be raised (each chain length of bytes in a daisy chain)",
     "CONFIRMED that CS must rise after each byte; UNCONFIRMED that only the last bytes are decoded (the shift register's reading)"},
    {Rule::COMMAND_SPLIT, "COMMAND_SPLIT",
     "a message of several frames ends while one chip still waits for argument bytes and another does not",
     "§9.2.1 Command management (Figure 19): argument bytes follow their command byte",
     "UNCONFIRMED (our heuristic: the chip sees bytes, not messages)"},
    {Rule::WRONG_CMD, "WRONG_CMD", "a byte that is no command, or SetParam/GetParam of a register the chip lacks",
     "§9.2.1 Command management (last paragraph), §9.2.3 SetParam; STATUS WRONG_CMD, §9.1.22 Table 34",
     "CONFIRMED (STATUS WRONG_CMD)"},
    {Rule::NOTPERF_CMD, "NOTPERF_CMD",
     "a command the chip refuses in its state: a WS/WH register written while running/not in HiZ, a motion command while busy",
     "§9.2.3 SetParam (write conditions, Table 9 registers map), §9.2.5-9.2.13; STATUS NOTPERF_CMD, §9.1.22",
     "CONFIRMED (STATUS NOTPERF_CMD, the write conditions of Table 9)"},
    {Rule::READ_ONLY_WRITE, "READ_ONLY_WRITE", "SetParam of a read-only register (SPEED, ADC_OUT, STATUS)",
     "§9.2.3 SetParam; Table 9 registers map (read-only: R)",
     "CONFIRMED that the registers are read-only; UNCONFIRMED which flag the chip raises"},
    {Rule::UNUSED_BITS, "UNUSED_BITS",
     "a value with bits its register or argument does not have: the chip drops them",
     "§9.2.3 SetParam and Table 9 (register lengths); §9.2.5-9.2.10 (argument widths)",
     "CONFIRMED for the register lengths; UNCONFIRMED that the chip drops the extra bits silently"},
    {Rule::ANSWER_LOST, "ANSWER_LOST",
     "a GetParam/GetStatus answer is replaced before the host clocked all its bytes out",
     "§9.2.1 Command management, Figure 21 (command response aborted)",
     "CONFIRMED (Figure 21: a new command aborts the response)"},
    {Rule::STANDBY_BYTE, "STANDBY_BYTE", "a command byte reaches a chip held in standby (STBY\\RST low): it is lost",
     "§6.12 Reset and standby",
     "UNCONFIRMED (the datasheet says the logic is reset in standby, not what a byte then does)"},
    {Rule::RESERVED_BITS, "RESERVED_BITS",
     "SetParam sets a bit the datasheet reserves: STEP_MODE bit 3 (L6470, L6480), CONFIG bit 6",
     "§9.1.19 Table 17 note 1 (STEP_MODE bit 3 written 0); §9.1.21 Table 22 (CONFIG bit 6 RESERVED)",
     "CONFIRMED that the L6470's STEP_MODE bit 3 is to be written 0; UNCONFIRMED what a 1 there or in CONFIG bit 6 does "
     "(the model stores it)"},
    {Rule::SPI_PINS, "SPI_PINS",
     "a CS frame with no clock edge, a frame that ends inside a byte, or clock edges while no chip select is low",
     "§8 Serial interface: a byte is eight CK rising edges with CS low; the byte in the register is decoded at the CS "
     "rising edge",
     "CONFIRMED that bytes take eight clocks with CS low; UNCONFIRMED what the chip decodes after a partial byte (the "
     "model drops its bits)"},
}};

std::string upper(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

std::vector<std::string> names() {
  std::vector<std::string> out;
  for (const RuleInfo& r : kRules) out.emplace_back(r.name);
  return out;
}

std::string quoted(std::string_view s) {
  std::string out = "'";
  for (char c : s.substr(0, 60)) out += (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) ? '?' : c;
  if (s.size() > 60) out += "\u2026";
  return out + "'";
}

}  // namespace

const std::array<RuleInfo, kRuleCount>& rule_table() { return kRules; }

const RuleInfo& rule_info(Rule rule) { return kRules[static_cast<std::size_t>(rule)]; }

std::optional<Rule> rule_named(std::string_view name) {
  const std::string u = upper(name);
  for (const RuleInfo& r : kRules)
    if (r.name == u) return r.rule;
  return std::nullopt;
}

std::string_view to_string(CheckLevel level) {
  switch (level) {
    case CheckLevel::off: return "off";
    case CheckLevel::warn: return "warn";
    case CheckLevel::error: return "error";
  }
  return "?";
}

std::optional<CheckLevel> parse_check_level(std::string_view text, std::string& error) {
  for (CheckLevel l : {CheckLevel::off, CheckLevel::warn, CheckLevel::error})
    if (text == to_string(l)) return l;
  const std::string near = closest_names(text, {"off", "warn", "error"});
  error = "must be off, warn or error, not " + quoted(text) + (near.empty() ? "" : " (did you mean " + near + "?)");
  return std::nullopt;
}

std::optional<RuleSet> parse_rule_list(std::string_view text, std::string& error) {
  RuleSet set;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t comma = text.find(',', start);
    if (comma == std::string_view::npos) comma = text.size();
    const std::string_view item = text.substr(start, comma - start);
    start = comma + 1;
    if (item.empty()) {
      error = "has an empty rule name in " + quoted(text) + " (write e.g. SPI_MODE,FRAME_LENGTH)";
      return std::nullopt;
    }
    const auto rule = rule_named(item);
    if (!rule) {
      const std::string near = closest_names(item, names());
      error = "names no rule " + quoted(item) + " (" + (near.empty() ? "" : "did you mean " + near + "? ") +
              "rules: " + all_rule_names() + ")";
      return std::nullopt;
    }
    set.insert(*rule);
  }
  return set;
}

std::string rule_list(const RuleSet& set) {
  std::string out;
  for (const RuleInfo& r : kRules)
    if (set.contains(r.rule)) out += (out.empty() ? "" : ",") + std::string(r.name);
  return out;
}

std::string all_rule_names() {
  std::string out;
  for (const RuleInfo& r : kRules) out += (out.empty() ? "" : ", ") + std::string(r.name);
  return out;
}

}  // namespace l6470emu
