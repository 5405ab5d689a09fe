// Markdown rendering of the register, STATUS and command tables.
#include "tools/tables.hpp"

#include "board/check_rules.hpp"
#include "tools/cmd_units.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "core/commands.hpp"

namespace l6470emu {
namespace {

std::string hex2(unsigned v) {
  char b[8];
  std::snprintf(b, sizeof b, "0x%02X", v);
  return b;
}

std::string flags_text(const RegisterInfo& r) {
  std::string s;
  if (r.is_signed()) s += "22-bit two's complement; ";
  if (r.is_live()) s += "computed by the model; ";
  if (r.flags & kWriteConflict) s += "write condition is a quirk (docs/quirks.md); ";
  if (r.flags & kUnconfirmed) s += "UNCONFIRMED (one source); ";
  if (!s.empty()) s.resize(s.size() - 2);
  return s;
}

/// The command table's "Argument bytes" cell of an opcode.
std::string argument_text(const Opcode& op) {
  switch (op.command) {
    case Command::SetParam: return "register length (1–3)";
    case Command::GetParam: return "0 (answer: register length)";
    case Command::GetStatus: return "0 (answer: 2)";
    case Command::Reserved: return "— (treated as unknown: WRONG_CMD)";
    default: return std::to_string(op.arg_bytes);
  }
}

}  // namespace

std::string register_table_markdown(const Variant& v) {
  std::string out = "| Addr | Register | Bits | SPI bytes | Reset | Write | Notes |\n|---|---|---|---|---|---|---|\n";
  for (unsigned a = 1; a < 32; ++a) {
    char row[192];
    if (const RegisterInfo* r = v.at_address(static_cast<std::uint8_t>(a)))
      std::snprintf(row, sizeof row, "| 0x%02X | %s | %u | %u | 0x%0*X | %s | %s |\n", r->address,
                    std::string(r->name).c_str(), r->bits, r->spi_bytes(), (r->bits + 3) / 4, r->reset,
                    std::string(to_string(r->access)).c_str(), flags_text(*r).c_str());
    else
      std::snprintf(row, sizeof row, "| 0x%02X | (none) | | | | | WRONG_CMD |\n", a);
    out += row;
  }
  return out;
}

std::string status_table_markdown(const Variant& v) {
  std::array<std::string, 16> names;
  const StatusLayout& l = v.status;
  auto put = [&](std::int8_t bit, const char* name) {
    if (bit < 0) return;
    if (!names[bit].empty()) names[bit] += " / ";
    names[bit] += name;
  };
  put(l.hiz, "HiZ");
  put(l.busy, "BUSY (low = busy)");
  put(l.sw_f, "SW_F");
  put(l.sw_evn, "SW_EVN (latched)");
  put(l.dir, "DIR (1 = forward)");
  if (l.mot_status >= 0) {
    put(static_cast<std::int8_t>(l.mot_status + 1), "MOT_STATUS[1]");
    put(l.mot_status, "MOT_STATUS[0]");
  }
  if (l.notperf_cmd == l.wrong_cmd) {
    put(l.wrong_cmd, "CMD_ERROR (latched)");
  } else {
    put(l.notperf_cmd, "NOTPERF_CMD (latched)");
    put(l.wrong_cmd, "WRONG_CMD (latched)");
  }
  put(l.uvlo, "UVLO (low = active, latched)");
  put(l.uvlo_adc, "UVLO_ADC (low = active, latched)");
  put(l.th_wrn, "TH_WRN (low = active, latched)");
  put(l.th_sd, "TH_SD (low = active, latched)");
  if (l.th_status >= 0) {
    put(static_cast<std::int8_t>(l.th_status + 1), "TH_STATUS[1]");
    put(l.th_status, "TH_STATUS[0]");
  }
  put(l.ocd, "OCD (low = active, latched)");
  put(l.step_loss_a, "STEP_LOSS_A / STALL_A (low = active, latched)");
  put(l.step_loss_b, "STEP_LOSS_B / STALL_B (low = active, latched)");
  put(l.sck_mod, "SCK_MOD (step-clock mode)");
  std::string out = "| Bit | Field |\n|---|---|\n";
  for (int bit = 15; bit >= 0; --bit)
    out += "| " + std::to_string(bit) + " | " +
           (!names[bit].empty() ? names[bit] : ((l.unused_ones >> bit) & 1u) ? "(unused, reads 1)" : "(unused, reads 0)") + " |\n";
  return out;
}

std::string variant_command_table_markdown(const Variant& v) {
  // The commands the variant's own opcode table decodes, each with its opcodes (a run of
  // SetParam/GetParam opcodes written first–last, holes left out).
  std::string out = "| Command | Opcodes | Argument bytes |\n|---|---|---|\n";
  std::vector<Command> order;
  for (unsigned b = 0; b < 256; ++b) {
    const Command c = v.opcodes[b].command;
    if (c != Command::Unknown && std::find(order.begin(), order.end(), c) == order.end()) order.push_back(c);
  }
  for (const Command c : order) {
    std::string list;
    for (unsigned b = 0; b < 256; ++b) {
      if (v.opcodes[b].command != c) continue;
      if (c == Command::SetParam || c == Command::GetParam) {
        if (b > 0 && v.opcodes[b - 1].command == c && b < 255 && v.opcodes[b + 1].command == c) continue;
        const bool starts = b == 0 || v.opcodes[b - 1].command != c;
        const bool ends = b == 255 || v.opcodes[b + 1].command != c;
        list += starts ? (list.empty() ? "" : ", ") + hex2(b) : "";
        if (ends && !starts) list += "–" + hex2(b);
      } else {
        list += (list.empty() ? "" : ", ") + hex2(b);
      }
    }
    const auto first = std::find_if(v.opcodes.begin(), v.opcodes.end(), [c](const Opcode& o) { return o.command == c; });
    out += "| " + std::string(to_string(c)) + " | " + list + " | " + argument_text(*first) + " |\n";
  }
  out += "| (any other byte) | | — (no command: WRONG_CMD) |\n";
  return out;
}

std::string command_table_markdown() {
  std::string out = "| Command | Opcodes | Argument bytes |\n|---|---|---|\n";
  // Group consecutive opcodes of the same command (DIR/ACT variants).
  int b = 0;
  while (b < 256) {
    const Opcode op = classify_opcode(static_cast<std::uint8_t>(b));
    if (op.command == Command::Unknown) { ++b; continue; }
    int e = b;
    std::string list;
    for (int x = b; x < 256; ++x) {
      const Opcode o = classify_opcode(static_cast<std::uint8_t>(x));
      if (o.command != op.command) {
        if (o.command == Command::Unknown && x - e < 9) continue;  // DIR/ACT variants have gaps
        break;
      }
      char h[8];
      std::snprintf(h, sizeof h, "0x%02X", x);
      if (o.command == Command::SetParam || o.command == Command::GetParam) {
        if (x == b) list = std::string(h);
        list = list.substr(0, 4) + "–" + h;
      } else {
        list += (list.empty() ? "" : ", ") + std::string(h);
      }
      e = x;
    }
    out += "| " + std::string(to_string(op.command)) + " | " + list + " | " + argument_text(op) + " |\n";
    b = e + 1;
  }
  return out;
}

namespace {

/// The columns of the variant tables: every variant, plus the powerSTEP01's current mode.
std::vector<std::pair<std::string, const Variant*>> variant_columns() {
  std::vector<std::pair<std::string, const Variant*>> cols;
  for (const Variant* v : all_variants()) {
    cols.emplace_back(std::string(v->name) + (v->current_mode ? " (voltage mode)" : ""), v);
    if (v->current_mode) cols.emplace_back(std::string(v->name) + " (current mode)", v->current_mode);
  }
  return cols;
}

std::string header_row(const std::vector<std::pair<std::string, const Variant*>>& cols, const char* first) {
  std::string out = std::string("| ") + first + " |";
  std::string rule = "|---|";
  for (const auto& c : cols) {
    out += " " + c.first + " |";
    rule += "---|";
  }
  return out + "\n" + rule + "\n";
}

/// Names of the STATUS fields on `bit` in layout `l`.
std::string status_bit_name(const StatusLayout& l, int bit) {
  std::string n;
  auto add = [&](bool here, std::string_view name) {
    if (!here) return;
    if (!n.empty()) n += "/";
    n += name;
  };
  add(l.hiz == bit, "HiZ");
  add(l.busy == bit, "BUSY");
  add(l.sw_f == bit, "SW_F");
  add(l.sw_evn == bit, "SW_EVN");
  add(l.dir == bit, "DIR");
  add(l.mot_status >= 0 && (bit == l.mot_status || bit == l.mot_status + 1), "MOT_STATUS");
  if (l.notperf_cmd == l.wrong_cmd) {
    add(l.wrong_cmd == bit, "CMD_ERROR");
  } else {
    add(l.notperf_cmd == bit, "NOTPERF_CMD");
    add(l.wrong_cmd == bit, "WRONG_CMD");
  }
  add(l.uvlo == bit, "UVLO");
  add(l.uvlo_adc == bit, "UVLO_ADC");
  add(l.th_wrn == bit, "TH_WRN");
  add(l.th_sd == bit, "TH_SD");
  add(l.th_status >= 0 && (bit == l.th_status || bit == l.th_status + 1), "TH_STATUS");
  add(l.ocd == bit, "OCD");
  add(l.step_loss_a == bit, l.step_loss_a_name);
  add(l.step_loss_b == bit, l.step_loss_b_name);
  add(l.sck_mod == bit, l.sck_mod == 8 ? "STCK_MOD" : "SCK_MOD");
  return n.empty() ? "–" : n;
}

}  // namespace

std::string variant_registers_markdown() {
  const auto cols = variant_columns();
  std::string out = header_row(cols, "Addr");
  for (unsigned a = 1; a < 32; ++a) {
    bool any = false;
    std::string row = "| " + hex2(a) + " |";
    for (const auto& c : cols) {
      const RegisterInfo* r = c.second->at_address(static_cast<std::uint8_t>(a));
      if (!r) {
        row += " – |";
        continue;
      }
      any = true;
      char cell[96];
      std::snprintf(cell, sizeof cell, " %s %u/0x%0*X/%s%s |", std::string(r->name).c_str(), r->bits, (r->bits + 3) / 4,
                    r->reset, std::string(to_string(r->access)).c_str(), (r->flags & kUnconfirmed) ? " †" : "");
      row += cell;
    }
    if (any) out += row + "\n";
  }
  out += "\nCells read NAME bits/reset/write condition; – is no register (an unknown command); "
         "† marks an UNCONFIRMED row (see the list below).\n";
  return out;
}

std::string variant_status_markdown() {
  std::vector<const Variant*> vs(all_variants().begin(), all_variants().end());
  std::string out = "| Bit |";
  std::string rule = "|---|";
  for (const Variant* v : vs) {
    out += " " + std::string(v->name) + " |";
    rule += "---|";
  }
  out += "\n" + rule + "\n";
  for (int bit = 15; bit >= 0; --bit) {
    out += "| " + std::to_string(bit) + " |";
    for (const Variant* v : vs) out += " " + status_bit_name(v->status, bit) + " |";
    out += "\n";
  }
  return out;
}

std::string variant_differences_markdown() {
  std::string out = "| | ";
  std::string rule = "|---|";
  for (const Variant* v : all_variants()) {
    out += std::string(v->name) + " | ";
    rule += "---|";
  }
  out.pop_back();
  out += "\n" + rule + "\n";
  auto row = [&](const char* what, auto cell) {
    out += std::string("| ") + what + " |";
    for (const Variant* v : all_variants()) out += " " + cell(*v) + " |";
    out += "\n";
  };
  row("motion", [](const Variant& v) {
    return std::string(v.motion_engine ? "speed profile generator" : "none: STCK pulses in the direction of DIR");
  });
  row("pins besides FLAG, STCK, STBY\\RST", [](const Variant& v) {
    std::string p;
    if (v.pins.busy_sync) p += "BUSY\\SYNC";
    if (v.pins.sw) p += std::string(p.empty() ? "" : ", ") + "SW";
    if (v.pins.dir) p += std::string(p.empty() ? "" : ", ") + "DIR";
    return p;
  });
  row("finest microstep", [](const Variant& v) { return "1/" + std::to_string(1 << v.max_step_sel); });
  row("ACC = 0xFFF", [](const Variant& v) {
    if (!v.has(Reg::ACC)) return std::string("–");
    return std::string(v.infinite_acceleration ? "infinite acceleration" : "ordinary value");
  });
  row("CONFIG / STATUS at", [](const Variant& v) { return hex2(v.find(Reg::CONFIG)->address) + " / " + hex2(v.find(Reg::STATUS)->address); });
  row("command errors", [](const Variant& v) {
    return std::string(v.status.wrong_cmd == v.status.notperf_cmd ? "CMD_ERROR (bit 7)" : "WRONG_CMD (8), NOTPERF_CMD (7)");
  });
  row("OCD_TH / STALL_TH bits", [](const Variant& v) {
    const RegisterInfo* s = v.find(Reg::STALL_TH);
    return std::to_string(v.find(Reg::OCD_TH)->bits) + " / " + (s ? std::to_string(s->bits) : std::string("–"));
  });
  row("ResetDevice with bridges on", [](const Variant& v) {
    if (v.opcodes[0xC0].command != Command::ResetDevice) return std::string("– (no ResetDevice)");
    return std::string(v.reset_device_needs_hiz ? "refused (CMD_ERROR) †" : "performed");
  });
  out += "\n**UNCONFIRMED choices** (each is covered by a test):\n\n";
  for (const Variant* v : all_variants())
    for (std::string_view u : v->unconfirmed) out += "* " + std::string(v->name) + ": " + std::string(u) + "\n";
  return out;
}

std::string sanitizer_rules_markdown() {
  std::string out = "| rule (check.allow=) | what it is about | datasheet | mark |\n|---|---|---|---|\n";
  for (const RuleInfo& r : rule_table())
    out += "| `" + std::string(r.name) + "` | " + std::string(r.about) + " | " + std::string(r.datasheet) + " | " +
           std::string(r.mark) + " |\n";
  return out;
}

std::string generated_block(std::string_view name) {
  if (name == "sanitizer-rules") return sanitizer_rules_markdown();
  if (name == "variant-registers") return variant_registers_markdown();
  if (name == "variant-status") return variant_status_markdown();
  if (name == "variant-differences") return variant_differences_markdown();
  if (name == "l6470-registers") return register_table_markdown(l6470());
  if (name == "l6470-status") return status_table_markdown(l6470());
  if (name == "commands") return command_table_markdown();
  if (name == "l6474-registers") return register_table_markdown(l6474());
  if (name == "l6474-status") return status_table_markdown(l6474());
  if (name == "l6474-commands") return variant_command_table_markdown(l6474());
  if (name == "units") return units_table_markdown();
  return "";
}

std::string refresh_generated_blocks(std::string_view text) {
  static constexpr std::string_view kBegin = "<!-- BEGIN generated:";
  std::string out;
  std::size_t pos = 0;
  while (true) {
    const std::size_t b = text.find(kBegin, pos);
    if (b == std::string_view::npos) break;
    const std::size_t name_end = text.find(" -->", b);
    if (name_end == std::string_view::npos) break;
    const std::string name(text.substr(b + kBegin.size(), name_end - b - kBegin.size()));
    const std::string end_marker = "<!-- END generated:" + name + " -->";
    const std::size_t e = text.find(end_marker, name_end);
    if (e == std::string_view::npos) break;
    out.append(text.substr(pos, name_end + 4 - pos));
    out += "\n" + generated_block(name);
    pos = e;
  }
  out.append(text.substr(pos));
  return out;
}

}  // namespace l6470emu
