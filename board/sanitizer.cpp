// The sanitizer: the reports and their rate limit (Sanitizer), and the checks of one chain's bus
// and chips (ChainChecker). What the chips do with a broken rule is the model's (chain_wire.cpp,
// core/chip.cpp); this names it.
#include "board/sanitizer.hpp"

#include <cstdio>

#include "daisychain/explain.hpp"
#include "daisychain/protocol_tracker.hpp"
#include "spi/message.hpp"

namespace l6470emu {
namespace {

/// How often each rule is logged in full per chain and chip.
constexpr std::uint64_t kRepeats = 10;

std::string hex_byte(std::uint8_t b) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", b);
  return buf;
}

std::string seconds(Tick tick) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "t=%.6f s", static_cast<double>(tick) / static_cast<double>(kTicksPerSecond));
  return buf;
}

std::string where(const Violation& v) {
  if (v.frame == 0) return "";
  std::string s = "frame " + std::to_string(v.frame);
  if (v.byte) s += ", byte " + std::to_string(*v.byte);
  return s;
}

std::string mode_consequence(unsigned mode) {
  switch (mode) {
    case 0:
      return "the host reads each chip's stale SDO latch as the first bit of a frame's first byte (an answer's top "
             "bit: CONFIG 0x2E88 reads 0x2E08)";
    case 1:
      return "MOSI reaches the chips one bit late, and the host reads each chip's stale SDO latch as the first bit of "
             "a frame's first byte";
    case 2:
      return "MISO reaches the host one bit late: every byte it reads is shifted right by one bit";
    default:
      return "";
  }
}

std::string command_name(Command c) { return std::string(to_string(c)); }

}  // namespace

// ---------------------------------------------------------------- reports

std::string violation_line(const Violation& v) {
  std::string s = v.chain + ": ";
  if (!v.chip.empty()) s += v.chip + ": ";
  s += std::string(rule_info(v.rule).name) + ": " + v.what;
  if (const std::string w = where(v); !w.empty()) s += " (" + w + ")";
  return s;
}

std::string violation_report(const Violation& v, FailureEnd end) {
  const RuleInfo& r = rule_info(v.rule);
  std::string s = "l6470emu: driver sanitizer: " + std::string(r.name) + " on " + v.chain;
  if (!v.chip.empty()) s += ", " + v.chip;
  if (const std::string w = where(v); !w.empty()) s += ", " + w;
  s += " (" + seconds(v.tick) + ")\n";
  s += "  what:      " + v.what + "\n";
  s += "  rule:      " + std::string(r.about) + "\n";
  s += "  datasheet: " + std::string(r.datasheet) + "\n";
  s += std::string(end == FailureEnd::run_ends ? "  (check=error: the run ends here."
                                              : "  (check=error: l6470emu.SanitizerError is raised here.") +
       " To allow this rule: check.allow=" + std::string(r.name) +
       " in the board description, L6470EMU_CHECK_ALLOW=" + std::string(r.name) + ", or check_allow=[\"" +
       std::string(r.name) + "\"] in Python)\n";
  return s;
}

Sanitizer::Sanitizer(CheckConfig config, LineSink log) : config_(config), log_(std::move(log)) {}

void Sanitizer::report(const Violation& v) {
  if (config_.level == CheckLevel::off || config_.allowed.contains(v.rule)) return;
  if (broken_++ == 0) first_broken_ = v;
  if (broken_sink_) broken_sink_(v);
  if (config_.level == CheckLevel::error) {
    if (failure_) return;  // one report: the first
    failure_ = v;  // the front ends the run with it (and says so in its log)
    return;
  }
  if (!log_) return;
  // A driver looping on a mistake must not flood the log: each rule is shown kRepeats times per
  // chain and chip, then counted, with a tally at every power of ten.
  const std::string key = v.chain + '\0' + v.chip_key + '\0' + std::string(rule_info(v.rule).name);
  const std::uint64_t n = ++seen_[key];
  if (n < kRepeats) {
    log_(violation_line(v));
  } else if (n == kRepeats) {
    log_(violation_line(v) + "  (further ones of this kind are counted, not shown)");
  } else {
    std::uint64_t p = kRepeats;
    while (p < n && p <= UINT64_MAX / 10) p *= 10;
    if (p == n) {
      std::string s = v.chain + ": ";
      if (!v.chip.empty()) s += v.chip + ": ";
      log_(s + std::string(rule_info(v.rule).name) + ": " + std::to_string(n) + " so far");
    }
  }
}

std::optional<std::string> Sanitizer::take_failure(FailureEnd end) {
  if (!failure_) return std::nullopt;
  std::string r = violation_report(*failure_, end);
  failure_.reset();
  return r;
}

// ---------------------------------------------------------------- one chain

ChainChecker::ChainChecker(Sanitizer& sanitizer, const Chain& chain, std::string name, NumberFrom numbering)
    : sanitizer_(sanitizer), chain_(chain), name_(std::move(name)), numbering_(numbering, chain.size()) {}

Violation ChainChecker::make(Rule rule, std::optional<std::size_t> chip, std::optional<std::uint64_t> byte,
                             std::string what) const {
  Violation v;
  v.rule = rule;
  v.chain = name_;
  if (chip) {
    v.chip = numbering_.label(*chip);
    v.chip_key = std::to_string(*chip);
  } else if (chain_.size() == 1) {
    v.chip = numbering_.label(0);
    v.chip_key = "0";
  } else {
    v.chip = "every chip";
  }
  v.frame = frame_;
  v.byte = byte;
  v.tick = chain_.now();
  v.what = std::move(what);
  return v;
}

void ChainChecker::check_cs_polarity(const WireSettings& wire) {
  reported_cs_high_ = wire.cs_active_high;
  if (wire.cs_active_high)
    sanitizer_.report(make(Rule::CS_ACTIVE_HIGH, std::nullopt, std::nullopt,
                           "the host asserts CS high; the chip's CS is active low, so it is never selected: no byte "
                           "reaches it and MISO reads 0x00"));
}

void ChainChecker::check_settings(const WireSettings& wire) {
  checked_ = wire;
  const std::optional<std::uint64_t> byte = frame_bytes_;
  const unsigned mode = wire.mode & 3u;
  if (mode != 3 && static_cast<int>(mode) != reported_mode_) {
    reported_mode_ = static_cast<int>(mode);
    sanitizer_.report(make(Rule::SPI_MODE, std::nullopt, byte,
                           "the host clocks in SPI mode " + std::to_string(mode) + " (CPOL=" + std::to_string(mode >> 1) +
                               ", CPHA=" + std::to_string(mode & 1u) +
                               "); the chip samples SDI on rising and changes SDO on falling clock edges, which only "
                               "mode 3 fits: " + mode_consequence(mode)));
  } else if (mode == 3) {
    reported_mode_ = -1;
  }
  if (wire.lsb_first && !reported_lsb_) {
    reported_lsb_ = true;
    sanitizer_.report(make(Rule::LSB_FIRST, std::nullopt, byte,
                           "the host shifts bytes least significant bit first; the chip reads, and answers, every byte "
                           "bit-reversed"));
  } else if (!wire.lsb_first) {
    reported_lsb_ = false;
  }
  const int bits = wire.bits_per_word == 0 ? 8 : wire.bits_per_word;
  if (bits != 8 && bits != reported_bits_) {
    reported_bits_ = bits;
    const int bytes = (bits + 7) / 8;
    sanitizer_.report(make(Rule::WORD_SIZE, std::nullopt, byte,
                           "the host clocks " + std::to_string(bits) + "-bit words; the chip frames 8-bit bytes: each "
                           "word reaches the chain as " + std::to_string(bytes) +
                               " bytes in the order the host shifts them, inside one CS frame"));
  } else if (bits == 8) {
    reported_bits_ = -1;
  }
  if (wire.speed_hz > kChipMaxSpeedHz && wire.speed_hz != reported_speed_) {
    reported_speed_ = wire.speed_hz;
    sanitizer_.report(make(Rule::SCK_SPEED, std::nullopt, byte,
                           "SCK is " + describe_speed(wire.speed_hz) +
                               "; the chip is specified up to 5 MHz (the emulator serves it as if it worked)"));
  } else if (wire.speed_hz <= kChipMaxSpeedHz) {
    reported_speed_ = 0;
  }
}

void ChainChecker::selected_checks(Tick tick, bool timed) {
  if (timed && last_frame_had_bytes_ && tick - last_deselect_ < kDeselectMinTicks) {
    const Tick high = tick - last_deselect_;
    sanitizer_.report(make(Rule::CS_DESELECT_TIME, std::nullopt, std::nullopt,
                           "CS was high for " + std::to_string(high * 250) + " ns before this frame (t_disCS is at least " +
                               std::to_string(kDeselectMinNs) +
                               " ns): the chips had no time to load their answers, so this frame's first bytes clock out "
                               "what they received"));
  }
  if (chain_.standby_in_frame()) {
    keep_mosi_ = true;
    mosi_.clear();
  }
}

void ChainChecker::clocked_checks(std::span<const std::uint8_t> tx, const WireSettings& wire, Tick tick) {
  {
    if (!(wire == checked_)) check_settings(wire);
    if (frame_bytes_ == 0 && wire.cs_setup_timed && wire.speed_hz != 0) {
      const Tick clocks = tx.size() * transfer_ticks(1, wire.speed_hz);
      const Tick first_edge = tick >= clocks ? tick - clocks : 0;
      if (first_edge < cs_fall_ + kCsSetupMinTicks) report_early_clock(first_edge);
    }
    if (keep_mosi_) mosi_.insert(mosi_.end(), tx.begin(), tx.end());
  }
}

void ChainChecker::report_early_clock(Tick first_edge) {
  const Tick setup = first_edge > cs_fall_ ? first_edge - cs_fall_ : 0;
  sanitizer_.report(make(Rule::CS_SETUP_TIME, std::nullopt, std::uint64_t{0},
                         "the first clock edge came " + std::to_string(setup * 250) + " ns after CS fell (t_setCS is at least " +
                             std::to_string(kCsSetupMinNs) + " ns)"));
}

void ChainChecker::spi_pins(std::optional<std::uint64_t> byte, std::string what) {
  if (!on()) return;
  sanitizer_.report(make(Rule::SPI_PINS, std::nullopt, byte, std::move(what)));
}

void ChainChecker::deselecting_checks() {
  const std::size_t n = chain_.size(), len = static_cast<std::size_t>(frame_bytes_);
  if (len == n) {
    // the usual frame
  } else if (len % n != 0) {
    std::string what = std::to_string(len) + " byte" + (len == 1 ? "" : "s") + " in a frame for a chain of " +
                       std::to_string(n) + ": ";
    if (len < n) {
      const std::size_t left = n - len;
      what += (left == 1 ? numbering_.label(0) + " decodes a byte" : std::to_string(left) + " chips decode bytes") +
              " left in the chain, not the host's, and the host's bytes land in chips they were not meant for";
    } else {
      what += "MOSI bytes 0.." + std::to_string(len - n - 1) + " pass through undecoded and chip k decodes MOSI byte " +
              (numbering_.from() == NumberFrom::miso ? std::to_string(len - n) + "+k" : std::to_string(len - 1) + "-k") +
              ": the host's bytes land in chips they were not meant for";
    }
    sanitizer_.report(make(Rule::FRAME_LENGTH, std::nullopt, std::nullopt, what));
  } else if (len > n) {
    std::string what;
    if (n == 1)
      what = "CS held low over " + std::to_string(len) + " bytes for a single chip: only the last one is decoded, the "
             "others pass through (the chip needs CS raised after every byte)";
    else
      what = std::to_string(len) + " bytes in a frame for a chain of " + std::to_string(n) + ": MOSI bytes 0.." +
             std::to_string(len - n - 1) + " pass through the chain undecoded (CS must rise after every " +
             std::to_string(n) + " bytes)";
    sanitizer_.report(make(Rule::FRAME_PASS_THROUGH, std::nullopt, std::nullopt, what));
  }
  if (keep_mosi_) {
    for (std::size_t k = 0; k < n; ++k) {
      if (chain_.peek_chip(k).spi_enabled()) continue;
      const auto b = mosi_byte_decoded_by(len, n, k);
      if (!b || *b >= mosi_.size() || mosi_[*b] == 0x00) continue;
      sanitizer_.report(make(Rule::STANDBY_BYTE, k, *b,
                             "in standby (STBY\\RST low): the command byte " + hex_byte(mosi_[*b]) + " is lost"));
    }
  }
}

void ChainChecker::check_decode(std::size_t k, const Chip& chip, std::uint8_t byte) {
  // An answer a new GetParam, GetStatus or ResetDevice drops, or a command's last argument byte
  // with bits the chip drops: the chips raise no flag for either, so the checker looks before
  // they decode.
  if (!chain_.hears_frame(k)) return;  // in standby, or missing the frame (a lost_frame fault)
  const std::size_t len = static_cast<std::size_t>(frame_bytes_);
  if (chip.arguments_missing() == 1) {
    check_unused_bits(k, chip, (chip.arguments_so_far() << 8) | byte, decoded_at(len, k));
    check_reserved_bits(k, chip, (chip.arguments_so_far() << 8) | byte, decoded_at(len, k));
    return;
  }
  // Only GetParam (0x20-0x3F), GetStatus and ResetDevice drop an answer.
  if (((byte & 0xE0) != 0x20 && byte != 0xD0 && byte != 0xC0) || chip.collecting_arguments()) return;
  const Command c = chip.variant().opcodes[byte].command;
  if (c != Command::GetParam && c != Command::GetStatus && c != Command::ResetDevice) return;
  const std::uint8_t pending = chip.answer_bytes_pending();
  sanitizer_.report(make(Rule::ANSWER_LOST, k, decoded_at(len, k),
                         std::to_string(pending) + " byte" + (pending == 1 ? "" : "s") +
                             " of an earlier answer never shifted out: " + opcode_name(byte, chip.registers()) +
                             (c == Command::ResetDevice ? " drops it" : " replaces it")));
}

std::optional<std::uint64_t> ChainChecker::decoded_at(std::size_t len, std::size_t chip) const {
  if (const auto b = mosi_byte_decoded_by(len, chain_.size(), chip)) return *b;
  return std::nullopt;
}

void ChainChecker::check_unused_bits(std::size_t k, const Chip& chip, std::uint32_t arg,
                                     std::optional<std::uint64_t> where) {
  // The bits of the argument bytes the command or register has; a signed position may carry its
  // sign into the bits above (a sign-extended value is the same position).
  const Opcode& op = chip.collecting_opcode();
  unsigned bits = 0;
  const unsigned bytes = op.arg_bytes;
  bool is_signed = false;
  std::string name, what;
  switch (op.command) {
    case Command::SetParam: {
      const RegisterInfo* r = chip.registers().at_address(op.param);
      if (r == nullptr || r->access == Access::R) return;
      bits = r->bits;
      is_signed = r->is_signed();
      name = "SetParam(" + std::string(r->name) + ")";
      what = "the register has";
      break;
    }
    case Command::Move: bits = 22; name = "Move"; what = "N_STEP has"; break;
    case Command::GoTo: bits = 22; is_signed = true; name = "GoTo"; what = "ABS_POS has"; break;
    case Command::GoTo_DIR: bits = 22; is_signed = true; name = "GoTo_DIR"; what = "ABS_POS has"; break;
    case Command::Run: bits = 20; name = "Run"; what = "SPD has"; break;
    case Command::GoUntil: bits = 20; name = "GoUntil"; what = "SPD has"; break;
    default: return;
  }
  if (bits >= 8 * bytes) return;
  const std::uint32_t all = bytes >= 4 ? 0xFFFFFFFFu : (1u << (8 * bytes)) - 1u;
  const std::uint32_t mask = (1u << bits) - 1u;
  const std::uint32_t extra = arg & all & ~mask;
  if (extra == 0) return;
  if (is_signed && ((arg >> (bits - 1)) & 1u) != 0 && extra == (all & ~mask)) return;  // sign-extended
  sanitizer_.report(make(Rule::UNUSED_BITS, k, where,
                         name + " value " + hex_value(arg & all, 8 * bytes) + " has bits above the " +
                             std::to_string(bits) + " " + what + " (" + hex_value(extra, 8 * bytes) +
                             "): the chip keeps " + hex_value(arg & mask, 8 * bytes)));
}

void ChainChecker::check_reserved_bits(std::size_t k, const Chip& chip, std::uint32_t arg,
                                       std::optional<std::uint64_t> where) {
  const Opcode& op = chip.collecting_opcode();
  if (op.command != Command::SetParam) return;
  const RegisterInfo* r = chip.registers().at_address(op.param);
  if (r == nullptr) return;
  for (const ReservedBit& b : chip.variant().reserved_bits)
    if (b.reg == r->id && ((arg >> b.bit) & 1u) != 0)
      sanitizer_.report(make(Rule::RESERVED_BITS, k, where,
                             "SetParam(" + std::string(r->name) + ") value " + hex_value(arg, 8 * op.arg_bytes) +
                                 " sets bit " + std::to_string(b.bit) + ", which is to be written 0: " +
                                 std::string(b.source)));
}

void ChainChecker::check_split() {
  const std::size_t n = chain_.size();
  std::optional<std::size_t> waiting, done;
  for (std::size_t k = 0; k < n; ++k) {
    const Chip& c = chain_.peek_chip(k);
    if (!c.spi_enabled()) continue;
    if (c.collecting_arguments()) {
      if (!waiting) waiting = k;
    } else if (!done) {
      done = k;
    }
  }
  if (!waiting || !done) return;
  const Chip& c = chain_.peek_chip(*waiting);
  const unsigned missing = c.arguments_missing();
  sanitizer_.report(make(Rule::COMMAND_SPLIT, *waiting, std::nullopt,
                         "a message of " + std::to_string(frames_in_use_) + " frames ends while this chip still waits for " +
                             std::to_string(missing) + " argument byte" + (missing == 1 ? "" : "s") + " of " +
                             command_name(c.collecting_command()) + " and " + numbering_.label(*done) +
                             " has finished its command: the next message's bytes for this chip complete the " +
                             command_name(c.collecting_command())));
}

void ChainChecker::chip_diagnostic(std::size_t chip, const Diagnostic& d) {
  if (!on()) return;
  Rule rule = Rule::WRONG_CMD;
  switch (d.kind) {
    case DiagnosticKind::wrong_cmd: rule = Rule::WRONG_CMD; break;
    case DiagnosticKind::notperf_cmd: rule = Rule::NOTPERF_CMD; break;
    case DiagnosticKind::ignored: return;
  }
  if (d.detail == DiagnosticDetail::read_only_write) rule = Rule::READ_ONLY_WRITE;
  std::optional<std::uint64_t> byte;
  std::string what = d.message;
  if (in_decode_) {
    if (const auto b = mosi_byte_decoded_by(static_cast<std::size_t>(frame_bytes_), chain_.size(), chip))
      byte = *b;
    else
      what += " (the byte was left in the chain by an earlier frame, not sent in this one)";
  }
  Violation v = make(rule, chip, byte, std::move(what));
  if (!in_decode_) v.frame = 0;
  sanitizer_.report(v);
}

}  // namespace l6470emu
