// `ctl` commands: status, get, sw, pin, fault, adc, axis, dump, chains, time, advance, trace.
#include "linux/serve/control.hpp"
#include "linux/serve/control_words.hpp"

#include <charconv>
#include <climits>
#include <cstdio>
#include <sstream>
#include <vector>

#include "core/axis_text.hpp"
#include "core/near_miss.hpp"
#include "core/status.hpp"
#include "linux/terminal_text.hpp"

namespace l6470emu {
namespace {

struct Args {
  std::vector<std::string> words;   // positional words after the command
  std::string chain;                // --chain NAME ("" = the first chain)
  long chip = -1;                   // --chip K as the user numbers it (-1 = not given)
  std::string chip_text;            // K as the user wrote it (a number too large for `chip` included)
  bool chip_too_large = false;      // K has more digits than any chain has chips
  std::optional<NumberFrom> number_from;  // --number-from miso|mosi (none = the board's)
  std::string error;
};

Args parse_args(const std::vector<std::string>& all) {
  Args a;
  for (std::size_t i = 1; i < all.size(); ++i) {
    const std::string& w = all[i];
    if (w == "--chain" || w == "--chip" || w == "--number-from") {
      if (i + 1 >= all.size()) {
        a.error = w + " needs a value";
        return a;
      }
      const std::string& v = all[++i];
      if (w == "--chain") {
        a.chain = v;
      } else if (w == "--number-from") {
        a.number_from = number_from_named(v);
        if (!a.number_from) a.error = "--number-from must be miso (chip 0 drives MISO) or mosi (chip 0 reads the host's MOSI), not '" + v + "'";
      } else {
        // Digits only, read exactly: a number past any chain's size is a chip that does not exist.
        a.chip_text = v;
        unsigned long long k = 0;
        const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), k, 10);
        if (v.empty() || end != v.data() + v.size() || (ec != std::errc{} && ec != std::errc::result_out_of_range)) {
          a.error = "--chip needs a chip number, not '" + terminal_safe(v.substr(0, 60)) + "'";
        } else if (ec == std::errc::result_out_of_range || k > static_cast<unsigned long long>(LONG_MAX)) {
          a.chip_too_large = true;
          a.chip = LONG_MAX;
        } else {
          a.chip = static_cast<long>(k);
        }
      }
    } else {
      a.words.push_back(w);
    }
  }
  return a;
}

}  // namespace

std::string parse_advance_ms(const std::string& text, Tick& ticks) {
  const std::string shown = "'" + terminal_safe(text.substr(0, 60)) + (text.size() > 60 ? "...'" : "'");
  const std::string form = " is not a time to advance by: write milliseconds as digits with at most 9 decimals "
                           "(e.g. 250 or 0.5), at most " + std::to_string(kMaxAdvanceMs) + " (about 115 days)";
  const std::size_t dot = text.find('.');
  const std::string_view whole = std::string_view(text).substr(0, dot);
  const std::string_view frac = dot == std::string::npos ? std::string_view() : std::string_view(text).substr(dot + 1);
  const auto digits = [](std::string_view s) {
    for (char c : s)
      if (c < '0' || c > '9') return false;
    return true;
  };
  if (whole.empty() || !digits(whole) || !digits(frac) || (dot != std::string::npos && frac.empty()) || frac.size() > 9)
    return shown + form;
  // Leading zeros do not count towards the bound's digits; past 11 digits it is too large anyway.
  const std::size_t first = std::min(whole.find_first_not_of('0'), whole.size());
  if (whole.size() - first > 11) return shown + " is more than " + std::to_string(kMaxAdvanceMs) + " ms (about 115 days)";
  std::uint64_t ms = 0;
  for (char c : whole.substr(first)) ms = ms * 10 + static_cast<std::uint64_t>(c - '0');
  std::uint64_t num = 0, den = 1;
  for (char c : frac) {
    num = num * 10 + static_cast<std::uint64_t>(c - '0');
    den *= 10;
  }
  if (ms > kMaxAdvanceMs || (ms == kMaxAdvanceMs && num > 0))
    return shown + " is more than " + std::to_string(kMaxAdvanceMs) + " ms (about 115 days)";
  constexpr Tick kTicksPerMs = 1000 * kTicksPerMicrosecond;
  ticks = ms * kTicksPerMs + num * kTicksPerMs / den;  // a fraction of a tick is dropped
  return "";
}

namespace {

std::string hex(std::uint32_t v, int digits) {
  char b[16];
  std::snprintf(b, sizeof b, "0x%0*X", digits, v);
  return b;
}

const RegisterInfo* register_named(const Variant& v, const std::string& name) {
  for (const RegisterInfo& r : v.registers)
    if (r.name == name) return &r;
  return nullptr;
}

}  // namespace

std::string control_help(std::optional<NumberFrom> numbering) {
  const std::string numbers = numbering ? describe_numbering(*numbering) + ", as the daemon's numbering= says"
                                        : "chip numbers count as the daemon's numbering= says (miso unless set: chip 0 "
                                          "drives MISO)";
  return "l6470emu ctl commands (--chain NAME picks a chain, default the first):\n"
         "  " + numbers + "; --number-from miso|mosi counts from the MISO or the MOSI end for one command\n"
         "  chains                              the emulated chains and their gpiochips\n"
         "  status [--chip K]                   STATUS of each chip, read without clearing anything\n"
         "  get REGISTER [--chip K]             a register as GetParam would return it, without side effects\n"
         "  dump                                every register of every chip, STATUS decoded, open files\n"
         "  clients                             the connected programs (pid), each through shared memory or the socket\n"
         "  sw open|closed --chip K             the limit switch on the SW pin (closed = pulled low)\n"
         "  pin SW|STCK|STBY_RST|DIR 0|1 --chip K   drive an input pin of a chip (DIR: an L6474's)\n"
         "  fault uvlo|uvlo-adc|ocd|stall-a|stall-b on|off --chip K\n"
         "  fault reset|lost-frame|miso-flip [BIT] --chip K   a brown-out; the chip deaf to, or one bit of its answer\n"
         "                                 flipped in, the chain's next frame\n"
         "  fault thermal normal|warning|bridge-shutdown|device-shutdown --chip K\n"
         "  adc CODE --chip K                   ADCIN conversion result, 0..31\n"
         "  axis [--chip K]                     the mechanics: true position next to ABS_POS, lost steps, switches\n"
         "  axis load ITEM,... --chip K         change the load at runtime: load=G_CM2,friction=NM,force=NM\n"
         "  time                                virtual time of each chain\n"
         "  advance MS                          virtual-time daemons: let MS milliseconds pass\n"
         "  trace start FILE                    record the chain's SPI frames, pins and faults (native trace)\n"
         "  trace stop                          stop recording (every chain, or the --chain one)\n";
}

int run_control(DeviceBoard& board, const std::string& command, std::string& out) {
  const std::vector<std::string> all = split_control_words(command);
  std::ostringstream o;
  if (all.empty() || all[0] == "help" || all[0] == "--help") {
    out = control_help(board.numbering());
    return all.empty() ? 2 : 0;
  }
  const std::string& cmd = all[0];
  Args a = parse_args(all);
  if (!a.error.empty()) {
    out = "ctl: " + a.error + "\n";
    return 2;
  }
  const NumberFrom number_from = a.number_from.value_or(board.numbering());
  if (board.chain_count() == 0) {
    out = "ctl: the daemon has no chain\n";
    return 1;
  }
  const int chain = a.chain.empty() ? 0 : board.find_chain(a.chain);
  if (chain < 0) {
    out = "ctl: no chain called '" + a.chain + "' (see `ctl chains`)\n";
    return 1;
  }
  const std::size_t ci = static_cast<std::size_t>(chain);
  std::size_t chips = 0;
  board.with_chain(ci, [&](Chain& c) { chips = c.size(); });
  if (a.chip_too_large || a.chip >= static_cast<long>(chips)) {
    out = "ctl: chip " + a.chip_text + " does not exist (the chain has " + std::to_string(chips) + ")\n";
    return 1;
  }
  // --chip K is the user's number; k below is always the chain index.
  const ChipNumbering numbering(number_from, chips);
  const auto label = [&](std::size_t k) { return numbering.label(k); };
  const auto said = [&] { o << "# " << numbering.description() << "\n"; };
  // Writes need a chip unless the chain has only one.
  auto target_chip = [&](std::size_t& k) {
    if (a.chip >= 0) {
      k = numbering.index_of(static_cast<std::size_t>(a.chip));
      return true;
    }
    if (chips == 1) {
      k = 0;
      return true;
    }
    out = "ctl: the chain has " + std::to_string(chips) + " chips: say which with --chip K\n";
    return false;
  };
  // Every chip in the user's order (or the --chip one), as chain indices.
  auto for_chips = [&](auto&& f) {
    const std::size_t lo = a.chip >= 0 ? static_cast<std::size_t>(a.chip) : 0;
    const std::size_t hi = a.chip >= 0 ? lo + 1 : chips;
    for (std::size_t u = lo; u < hi; ++u) f(numbering.index_of(u));
  };

  if (cmd == "chains") {
    for (std::size_t i = 0; i < board.chain_count(); ++i) o << board.chain_summary(i) << "\n";
    said();
  } else if (cmd == "status") {
    said();
    board.with_chain(ci, [&](Chain& c) {
      for_chips([&](std::size_t k) {
        const Chip& chip = c.chip(k);
        o << label(k) << " (" << chip.variant().name << "): STATUS " << hex(chip.status(), 4) << "  "
          << describe_status(chip.variant().status, chip.status());
        if (const Axis* axis = chip.axis())
          o << "  ABS_POS " << chip.position() << " true " << axis->true_position();
        o << "\n";
      });
    });
  } else if (cmd == "get") {
    if (a.words.size() != 1) {
      out = "ctl: usage: get REGISTER [--chip K]\n";
      return 2;
    }
    bool ok = true;
    board.with_chain(ci, [&](Chain& c) {
      for_chips([&](std::size_t k) {
        const Chip& chip = c.chip(k);
        const RegisterInfo* r = register_named(chip.variant(), a.words[0]);
        if (!r) {
          ok = false;
          return;
        }
        const std::uint32_t v = chip.peek(r->id);
        o << label(k) << ": " << r->name << " = " << hex(v, (r->bits + 3) / 4);
        if (r->is_signed()) o << " (" << sign_extend(v, r->bits) << ")";
        o << "\n";
      });
    });
    if (!ok) {
      std::vector<std::string> names;
      board.with_chain(ci, [&](Chain& c) {
        for (const RegisterInfo& r : c.chip(0).registers().registers) names.emplace_back(r.name);
      });
      const std::string near = closest_names(terminal_safe(a.words[0]), names);
      out = "ctl: no register '" + terminal_safe(a.words[0]) + "' on this variant" +
            (near.empty() ? " (use the datasheet name, e.g. ABS_POS)" : "; did you mean " + near + "?") + "\n";
      return 1;
    }
  } else if (cmd == "dump") {
    said();
    board.with_chain(ci, [&](Chain& c) {
      for_chips([&](std::size_t k) { o << "== " << label(k) << " ==\n" << c.chip(k).dump() << "\n"; });
    });
    o << board.describe_handles();
  } else if (cmd == "sw" || cmd == "pin") {
    std::size_t k = 0;
    if (!target_chip(k)) return 2;
    Pin pin = Pin::SW;
    bool level = true;
    if (cmd == "sw") {
      if (a.words.size() != 1 || (a.words[0] != "open" && a.words[0] != "closed")) {
        out = "ctl: usage: sw open|closed --chip K\n";
        return 2;
      }
      level = a.words[0] == "open";
    } else {
      if (a.words.size() != 2 || (a.words[1] != "0" && a.words[1] != "1")) {
        out = "ctl: usage: pin SW|STCK|STBY_RST|DIR 0|1 --chip K\n";
        return 2;
      }
      if (a.words[0] == "SW")
        pin = Pin::SW;
      else if (a.words[0] == "STCK")
        pin = Pin::STCK;
      else if (a.words[0] == "STBY_RST" || a.words[0] == "STBY" || a.words[0] == "RST")
        pin = Pin::STBY_RST;
      else if (a.words[0] == "DIR")
        pin = Pin::DIR;
      else {
        out = "ctl: pin must be SW, STCK, STBY_RST or DIR (BUSY and FLAG are the chip's outputs)\n";
        return 2;
      }
      level = a.words[1] == "1";
    }
    if (!board.drive_pin(ci, k, pin, level)) {
      out = "ctl: " + label(k) + " has no " + pin_name(pin) + " pin\n";
      return 2;
    }
    o << label(k) << ": " << pin_name(pin) << " " << (level ? "high" : "low") << "\n";
  } else if (cmd == "fault") {
    std::size_t k = 0;
    if (!target_chip(k)) return 2;
    // The one-shot events: a brown-out, and the wire's faults on the chain's next frame.
    const std::string first = a.words.empty() ? std::string() : a.words[0];
    if (first == "reset" || first == "lost-frame" || first == "miso-flip") {
      char* end = nullptr;
      const long bit = first == "miso-flip" && a.words.size() == 2 ? std::strtol(a.words[1].c_str(), &end, 10) : 7;
      if (a.words.size() > (first == "miso-flip" ? 2u : 1u) || (end && (*end || bit < 0 || bit > 7))) {
        out = "ctl: usage: fault reset|lost-frame --chip K, or fault miso-flip [BIT 0..7] --chip K\n";
        return 2;
      }
      const TraceFault fault = first == "reset" ? TraceFault::POWER_CYCLE
                               : first == "lost-frame" ? TraceFault::LOST_FRAME : TraceFault::MISO_FLIP;
      board.inject_fault(ci, k, fault, first == "miso-flip" ? static_cast<std::uint8_t>(bit) : 0);
      o << label(k) << ": " << first << (first == "miso-flip" ? " bit " + std::to_string(bit) : std::string()) << "\n";
      out = o.str();
      return 0;
    }
    if (a.words.size() != 2) {
      out = "ctl: usage: fault NAME on|off --chip K (or: fault thermal LEVEL; fault reset|lost-frame|miso-flip [BIT])\n";
      return 2;
    }
    const std::string& f = a.words[0];
    const std::string& v = a.words[1];
    if (f == "thermal") {
      Thermal t;
      if (v == "normal") t = Thermal::normal;
      else if (v == "warning") t = Thermal::warning;
      else if (v == "bridge-shutdown" || v == "shutdown") t = Thermal::bridge_shutdown;
      else if (v == "device-shutdown") t = Thermal::device_shutdown;
      else {
        out = "ctl: thermal level must be normal, warning, bridge-shutdown or device-shutdown\n";
        return 2;
      }
      board.inject_fault(ci, k, TraceFault::THERMAL, static_cast<std::uint8_t>(t));
    } else {
      if (v != "on" && v != "off") {
        out = "ctl: fault state must be on or off\n";
        return 2;
      }
      const bool on = v == "on";
      TraceFault fault = TraceFault::UVLO;
      bool known = true;
      if (f == "uvlo") fault = TraceFault::UVLO;
      else if (f == "uvlo-adc") fault = TraceFault::UVLO_ADC;
      else if (f == "ocd") fault = TraceFault::OCD;
      else if (f == "stall-a") fault = TraceFault::STALL_A;
      else if (f == "stall-b") fault = TraceFault::STALL_B;
      else known = false;
      if (known) board.inject_fault(ci, k, fault, on ? 1 : 0);
      if (!known) {
        out = "ctl: unknown fault '" + f + "' (uvlo, uvlo-adc, ocd, stall-a, stall-b, thermal, reset, lost-frame, miso-flip)\n";
        return 2;
      }
    }
    o << label(k) << ": " << f << " " << v << "\n";
  } else if (cmd == "adc") {
    std::size_t k = 0;
    if (!target_chip(k)) return 2;
    char* end = nullptr;
    const long code = a.words.size() == 1 ? std::strtol(a.words[0].c_str(), &end, 10) : -1;
    if (a.words.size() != 1 || *end || code < 0 || code > 31) {
      out = "ctl: usage: adc CODE --chip K (CODE 0..31)\n";
      return 2;
    }
    board.inject_fault(ci, k, TraceFault::ADCIN, static_cast<std::uint8_t>(code));
    o << label(k) << ": ADC_OUT " << code << "\n";
  } else if (cmd == "axis") {
    if (!a.words.empty() && a.words[0] == "load") {
      std::size_t k = 0;
      if (!target_chip(k)) return 2;
      if (a.words.size() != 2) {
        out = "ctl: usage: axis load ITEM,... --chip K (load=G_CM2, friction=NM, force=NM)\n";
        return 2;
      }
      std::string error;
      bool has_axis = true;
      LoadSpec load;
      board.with_chain(ci, [&](Chain& c) {
        const Chip& chip = c.chip(k);
        if (!chip.axis()) {
          has_axis = false;
          return;
        }
        load = chip.axis()->spec().load;
        error = parse_axis_load(a.words[1], load);
      });
      if (has_axis && error.empty()) board.set_axis_load(ci, k, load);  // recorded when recording
      if (!has_axis) {
        out = "ctl: " + label(k) + " has no axis (axis.K= in the board description)\n";
        return 1;
      }
      if (!error.empty()) {
        out = "ctl: axis load: " + error + "\n";
        return 2;
      }
      o << label(k) << ": load " << a.words[1] << "\n";
    } else if (!a.words.empty()) {
      out = "ctl: usage: axis [--chip K] | axis load ITEM,... --chip K\n";
      return 2;
    } else {
      board.with_chain(ci, [&](Chain& c) {
        for_chips([&](std::size_t k) {
          const Chip& chip = c.chip(k);
          const Axis* axis = chip.axis();
          o << label(k) << ": ";
          if (!axis) {
            o << "no axis\n";
            return;
          }
          o << "ABS_POS " << chip.position() << "  true " << axis->true_position() << " (1/128 step)  lost "
            << axis->lost_steps() << "  " << (axis->synchronised() ? "synchronised" : "stalled")
            << (axis->at_stop() ? " at a hard stop" : "") << "  " << axis->phase_current_mA() << " mA  torque "
            << axis->available_torque_uNm() << "/" << axis->required_torque_uNm() << " uNm";
          for (std::size_t i = 0; i < axis->spec().switches.size(); ++i)
            o << "  " << axis->spec().switches[i].name << " " << (axis->switch_closed(i) ? "closed" : "open");
          o << "  SW " << (chip.sw_pin() ? "high" : "low") << "\n";
        });
      });
    }
  } else if (cmd == "time") {
    for (std::size_t i = 0; i < board.chain_count(); ++i) {
      const Tick t = board.now(i);
      char b[96];
      std::snprintf(b, sizeof b, "%llu ticks = %.6f s", static_cast<unsigned long long>(t),
                    static_cast<double>(t) / static_cast<double>(kTicksPerSecond));
      o << board.chain_summary(i) << ": " << b << "\n";
    }
    o << (board.time().is_virtual() ? "virtual time (moves with bus traffic and `advance`)\n"
                                    : "wall clock x " + std::to_string(board.time().scale()) + "\n");
  } else if (cmd == "advance") {
    if (a.words.size() != 1) {
      out = "ctl: usage: advance MS\n";
      return 2;
    }
    Tick ticks = 0;
    if (const std::string error = parse_advance_ms(a.words[0], ticks); !error.empty()) {
      out = "ctl: advance: " + error + "\n";
      return 2;
    }
    if (!board.time().is_virtual()) {
      out = "ctl: the daemon runs on the wall clock; `advance` needs `serve --virtual-time`\n";
      return 1;
    }
    // The clock ends one tick before kNever (about 146 000 years): it never wraps round to the start.
    if (const Tick now = board.time().now(); ticks > kNever - 1 - now) {
      out = "ctl: advance: the board's clock is at " + std::to_string(now) + " ticks and ends at " +
            std::to_string(kNever - 1) + ": it cannot move on by " + std::to_string(ticks) + " ticks\n";
      return 1;
    }
    board.advance(ticks);
    o << "advanced " << a.words[0] << " ms (" << ticks << (ticks == 1 ? " tick)\n" : " ticks)\n");
  } else if (cmd == "trace") {
    // One native trace per chain; without --chain, `stop` ends every recording.
    if (a.words.size() == 2 && a.words[0] == "start") {
      // A recording in progress (serve --record, an earlier ctl) is never ended behind its back.
      if (const std::string now = board.recording_path(ci); !now.empty()) {
        out = "ctl: " + board.chain_summary(ci) + " is already being recorded to " + now +
              "; `ctl trace stop` ends that recording first\n";
        return 1;
      }
      if (const std::string error = board.start_recording(ci, a.words[1]); !error.empty()) {
        out = "ctl: " + error + "\n";
        return 1;
      }
      o << board.chain_summary(ci) << ": recording to " << a.words[1] << "\n";
    } else if (a.words.size() == 1 && a.words[0] == "stop") {
      bool any = false;
      for (std::size_t i = 0; i < board.chain_count(); ++i) {
        if (!a.chain.empty() && i != ci) continue;
        std::string summary;
        if (board.stop_recording(i, &summary)) {
          any = true;
          o << board.chain_summary(i) << ": recorded " << summary << "\n";
        }
      }
      if (!any) {
        out = "ctl: nothing is being recorded\n";
        return 1;
      }
    } else {
      out = "ctl: usage: trace start FILE [--chain NAME] | trace stop [--chain NAME]\n";
      return 2;
    }
  } else {
    out = "ctl: " + unknown_control_command(cmd) + " (ctl help lists them)\n";
    return 2;
  }
  out = o.str();
  return 0;
}

const std::vector<std::string>& control_commands() {
  static const std::vector<std::string> commands{"status", "get",  "dump",    "sw",    "pin",     "fault", "adc",
                                                 "axis",   "time", "advance", "chains", "trace", "clients", "help"};
  return commands;
}

std::string unknown_control_command(const std::string& word) {
  const std::string near = closest_names(word, control_commands());
  return "unknown command '" + terminal_safe(word) + "'" + (near.empty() ? "" : "; did you mean " + near + "?");
}

}  // namespace l6470emu
