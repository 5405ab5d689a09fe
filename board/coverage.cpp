// Interface coverage points, derived from the variant tables, and the data of runs (JSON).
#include "board/coverage.hpp"

#include <algorithm>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "board/board_config.hpp"
#include "board/check_rules.hpp"
#include "spi/trace.hpp"

namespace l6470emu {

namespace {

constexpr std::string_view kCategoryNames[] = {
    "commands",       "registers read", "registers written", "refusals",    "flags raised", "flags observed",
    "events",         "step modes",     "chain positions",   "pin edges",   "rules broken"};
static_assert(std::size(kCategoryNames) == kCoverageCategoryCount);

std::string key(CoverageCategory c, std::string_view name) {
  std::string k(to_string(c));
  k += '\t';
  k += name;
  return k;
}

/// What a value of a command's argument can be that the chip treats apart.
struct ArgumentClass {
  Command command;
  std::string_view name;
  std::string_view about;
};
constexpr ArgumentClass kArgumentClasses[] = {
    {Command::Run, "Run above MAX_SPEED", "Run with SPD above MAX_SPEED: the chip runs at MAX_SPEED"},
    {Command::Move, "Move of 0 steps", "Move with N = 0: a command that moves nothing"},
    {Command::GoTo, "GoTo to the current position", "GoTo ABS_POS's own value: nothing to travel"},
    {Command::GoTo_DIR, "GoTo_DIR to the current position", "GoTo_DIR ABS_POS's own value: nothing to travel"},
};


/// The tables a variant can read its registers through (a powerSTEP01 has two).
std::vector<const Variant*> tables_of(const Variant& v) {
  std::vector<const Variant*> t{&v};
  if (v.current_mode) t.push_back(v.current_mode);
  return t;
}

std::string hex_byte(unsigned b) {
  static const char kDigits[] = "0123456789ABCDEF";
  return std::string("0x") + kDigits[(b >> 4) & 15u] + kDigits[b & 15u];
}

}  // namespace

std::string_view to_string(CoverageCategory c) {
  const auto i = static_cast<std::size_t>(c);
  return i < kCoverageCategoryCount ? kCategoryNames[i] : "?";
}

CoverageCategory coverage_category_named(std::string_view name) {
  for (std::size_t i = 0; i < kCoverageCategoryCount; ++i)
    if (kCategoryNames[i] == name) return static_cast<CoverageCategory>(i);
  return CoverageCategory::count;
}

std::vector<StatusFlagPoint> status_flag_points(const StatusLayout& l) {
  std::vector<StatusFlagPoint> f;
  auto bit = [&](std::string_view name, std::int8_t at, bool low, bool alarm) {
    if (at >= 0) f.push_back({std::string(name), at, low, -1, alarm});
  };
  bit("HiZ", l.hiz, false, false);
  bit("BUSY", l.busy, true, false);
  bit("SW_F", l.sw_f, false, false);
  bit("SW_EVN", l.sw_evn, false, true);
  bit("DIR", l.dir, false, false);
  if (l.mot_status >= 0) {
    f.push_back({"MOT_STATUS acceleration", l.mot_status, false, 1, false});
    f.push_back({"MOT_STATUS deceleration", l.mot_status, false, 2, false});
    f.push_back({"MOT_STATUS constant speed", l.mot_status, false, 3, false});
  }
  if (l.notperf_cmd == l.wrong_cmd) {
    bit("CMD_ERROR", l.wrong_cmd, false, true);
  } else {
    bit("NOTPERF_CMD", l.notperf_cmd, false, true);
    bit("WRONG_CMD", l.wrong_cmd, false, true);
  }
  bit("UVLO", l.uvlo, true, true);
  bit("UVLO_ADC", l.uvlo_adc, true, true);
  bit("TH_WRN", l.th_wrn, true, true);
  bit("TH_SD", l.th_sd, true, true);
  if (l.th_status >= 0) {
    f.push_back({"TH_STATUS warning", l.th_status, false, 1, true});
    f.push_back({"TH_STATUS bridge shutdown", l.th_status, false, 2, true});
    f.push_back({"TH_STATUS device shutdown", l.th_status, false, 3, true});
  }
  bit("OCD", l.ocd, true, true);
  bit(l.step_loss_a_name, l.step_loss_a, true, true);
  bit(l.step_loss_b_name, l.step_loss_b, true, true);
  bit("SCK_MOD", l.sck_mod, false, false);
  return f;
}

CoverageUniverse::CoverageUniverse(const Variant& v) : variant_(v.name) {
  auto add = [&](CoverageCategory c, std::string name, std::string about) {
    if (index_.count(key(c, name))) return;
    index_.emplace(key(c, name), static_cast<int>(points_.size()));
    points_.push_back({c, std::move(name), std::move(about)});
  };
  const auto tables = tables_of(v);

  // Commands: every command the opcode table decodes, split by the opcode bits the chip
  // reads (DIR, ACT), then the argument values it treats apart. SetParam and GetParam are
  // the registers' categories; NOP moves nothing.
  for (unsigned b = 0; b < 256; ++b) {
    const Opcode& op = v.opcodes[b];
    switch (op.command) {
      case Command::NOP: case Command::SetParam: case Command::GetParam: case Command::Reserved: case Command::Unknown:
        continue;
      default: break;
    }
    const std::string name(to_string(op.command));
    const bool has_dir = v.opcodes[b | 1u].command == op.command && v.opcodes[b | 1u].dir != v.opcodes[b & ~1u].dir;
    const bool has_act = op.command == Command::GoUntil || op.command == Command::ReleaseSW;
    if (has_dir) add(CoverageCategory::commands, name + (op.dir ? " FWD" : " REV"), name + " with DIR = " + (op.dir ? "1 (forward)" : "0 (reverse)"));
    else if (!has_act) add(CoverageCategory::commands, name, name + " (opcode " + hex_byte(b) + ")");
    if (has_act) add(CoverageCategory::commands, name + (op.act ? " ACT=1" : " ACT=0"),
                     name + (op.act ? " with ACT = 1: ABS_POS copied to MARK" : " with ACT = 0: ABS_POS reset"));
    for (const ArgumentClass& a : kArgumentClasses)
      if (a.command == op.command) add(CoverageCategory::commands, std::string(a.name), std::string(a.about));
  }
  // Registers, by address through each table the variant reads them with.
  for (const Variant* t : tables)
    for (const RegisterInfo& r : t->registers) add(CoverageCategory::registers_read, std::string(r.name), "GetParam(" + std::string(r.name) + ")");
  for (const Variant* t : tables)
    for (const RegisterInfo& r : t->registers)
      if (r.access != Access::R)
        add(CoverageCategory::registers_written, std::string(r.name),
            "SetParam(" + std::string(r.name) + ") accepted (" + std::string(to_string(r.access)) + ")");
  // Refusals: each write condition of the tables, then the commands' own.
  for (const Variant* t : tables)
    for (const RegisterInfo& r : t->registers)
      if (r.access == Access::WS || r.access == Access::WH)
        add(CoverageCategory::refusals, "SetParam(" + std::string(r.name) + ")",
            std::string(r.access == Access::WS ? "WS: written while the motor runs" : "WH: written while the bridges are enabled"));
  add(CoverageCategory::refusals, "SetParam of a read-only register", "SetParam of an R register");
  if (v.motion_engine) {  // the L6474 has no motion command to refuse
    add(CoverageCategory::refusals, "Move while the motor runs", "Move sent while the motor is not stopped");
    add(CoverageCategory::refusals, "StepClock while the motor runs", "StepClock sent while the motor is not stopped");
    for (const Command c : {Command::GoTo, Command::GoTo_DIR, Command::GoHome, Command::GoMark})
      add(CoverageCategory::refusals, std::string(to_string(c)) + " while BUSY", std::string(to_string(c)) + " sent before the last command ended");
    add(CoverageCategory::refusals, "motion command while a fault holds HiZ",
        "a motion command while thermal shutdown, UVLO or an overcurrent keeps the bridges off");
  }
  if (v.reset_device_needs_hiz)
    add(CoverageCategory::refusals, "ResetDevice while the bridges are enabled", "ResetDevice sent with the bridges on");
  add(CoverageCategory::refusals, "an opcode that is no command", "a byte the chip does not know as an opcode (WRONG_CMD)");
  // STATUS flags, once raised and once observed.
  for (const CoverageCategory c : {CoverageCategory::flags_raised, CoverageCategory::flags_observed})
    for (const StatusFlagPoint& f : status_flag_points(v.status))
      add(c, f.name, c == CoverageCategory::flags_raised ? f.name + " set in STATUS" : f.name + " set when the driver read STATUS or the pin");
  // Faults and switch events.
  auto fault = [&](TraceFault t, std::string_view about) {
    add(CoverageCategory::events, std::string(to_string(t)), std::string(about));
  };
  fault(TraceFault::UVLO, "the motor supply fell below its threshold");
  if (v.status.uvlo_adc >= 0) fault(TraceFault::UVLO_ADC, "the ADC input fell below its threshold");
  fault(TraceFault::OCD, "an overcurrent");
  if (v.status.step_loss_a >= 0) fault(TraceFault::STALL_A, "a stall on bridge A");
  if (v.status.step_loss_b >= 0) fault(TraceFault::STALL_B, "a stall on bridge B");
  for (std::uint8_t t = 1; t <= 3; ++t)
    add(CoverageCategory::events, "THERMAL " + std::string(thermal_name(t)), "the die reached the " + std::string(thermal_name(t)) + " class");
  fault(TraceFault::ADCIN, "the ADCIN level changed");
  fault(TraceFault::POWER_CYCLE, "a brown-out: the chip restarted");
  fault(TraceFault::MISO_FLIP, "a bit of the chip's answer flipped on the wire");
  fault(TraceFault::LOST_FRAME, "the chip missed a frame");
  if (v.pins.sw) {
    add(CoverageCategory::events, "SW closed", "the SW pin went low (a switch closed)");
    add(CoverageCategory::events, "SW opened", "the SW pin went high again");
  }
  add(CoverageCategory::events, "STBY_RST reset", "STBY\\RST held low, then released");
  // Step modes.
  std::uint8_t finest = 0;
  for (const Variant* t : tables) finest = std::max(finest, t->max_step_sel);
  // The L6474 moves by STCK pulses: its step mode is the one its Enable drives them in.
  const std::string driven_by = v.motion_engine ? "a motion command" : "Enable (the size of its STCK steps)";
  for (std::uint8_t s = 0; s <= finest && s < 8; ++s)
    add(CoverageCategory::step_modes, std::string(step_mode_name(s)), driven_by + " with STEP_SEL = " + std::to_string(s));
  // Pin edges (BUSY only on a part that has the pin).
  for (const char* pin : {"BUSY", "FLAG"}) {
    if (std::string_view(pin) == "BUSY" && !v.pins.busy_sync) continue;
    for (const char* edge : {"falling", "rising"})
      add(CoverageCategory::pin_edges, std::string(pin) + " " + edge,
          std::string("the program waited for ") + pin + " " + edge + " (an edge event, or a read in a loop)");
  }
  // Sanitizer rules.
  for (const RuleInfo& r : rule_table()) add(CoverageCategory::rules_broken, std::string(r.name), std::string(r.about));
}

int CoverageUniverse::find(CoverageCategory c, std::string_view name) const {
  const auto it = index_.find(key(c, name));
  return it == index_.end() ? -1 : it->second;
}

const CoverageUniverse& coverage_universe(const Variant& variant) {
  static const std::vector<std::unique_ptr<CoverageUniverse>> all = [] {
    std::vector<std::unique_ptr<CoverageUniverse>> u;
    for (const Variant* v : all_variants()) u.push_back(std::make_unique<CoverageUniverse>(*v));
    return u;
  }();
  for (const auto& u : all)
    if (u->variant() == variant.name) return *u;
  throw std::logic_error("coverage: no universe for " + std::string(variant.name));
}

const CoverageUniverse* coverage_universe(std::string_view name) {
  for (const Variant* v : all_variants())
    if (v->name == name) return &coverage_universe(*v);
  return nullptr;
}

std::string_view step_mode_name(std::uint8_t step_sel) {
  static constexpr std::string_view kModes[] = {"full step", "1/2", "1/4", "1/8", "1/16", "1/32", "1/64", "1/128"};
  return kModes[step_sel & 7u];
}

std::string chain_position_name(std::size_t number, std::size_t chips) {
  return "chip " + std::to_string(number) + " of " + std::to_string(chips);
}

bool is_chain_position_name(std::string_view name) {
  // "chip K of N": K < N, plain decimal numbers without leading zeros, as chain_position_name writes them.
  auto number = [&](std::size_t& at, std::uint64_t& out) {
    const std::size_t start = at;
    out = 0;
    while (at < name.size() && name[at] >= '0' && name[at] <= '9' && at - start < 9) out = out * 10 + static_cast<unsigned>(name[at++] - '0');
    return at > start && (at - start == 1 || name[start] != '0');
  };
  std::size_t at = 0;
  std::uint64_t k = 0, n = 0;
  if (name.substr(0, 5) != "chip ") return false;
  at = 5;
  if (!number(at, k) || name.substr(at, 4) != " of ") return false;
  at += 4;
  return number(at, n) && at == name.size() && k < n;
}

void CoverageData::merge(const CoverageData& other) {
  for (const auto& [name, o] : other.variants_) {
    PerVariant& mine = variants_[name];
    for (std::size_t c = 0; c < kCoverageCategoryCount; ++c) mine.hit[c].insert(o.hit[c].begin(), o.hit[c].end());
    mine.positions.insert(o.positions.begin(), o.positions.end());
  }
}

std::string CoverageData::to_json() const {
  nlohmann::ordered_json j;
  j["format"] = "l6470emu-coverage";
  j["version"] = kCoverageFormatVersion;
  nlohmann::ordered_json vs = nlohmann::ordered_json::object();
  for (const auto& [name, v] : variants_) {
    nlohmann::ordered_json o;
    o["chain positions present"] = v.positions;
    nlohmann::ordered_json hit = nlohmann::ordered_json::object();
    for (std::size_t c = 0; c < kCoverageCategoryCount; ++c)
      if (!v.hit[c].empty()) hit[std::string(to_string(static_cast<CoverageCategory>(c)))] = v.hit[c];
    o["hit"] = hit;
    vs[name] = o;
  }
  j["variants"] = vs;
  return j.dump(1) + "\n";
}

CoverageData CoverageData::from_json(std::string_view text) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception&) {
    throw std::runtime_error("not a coverage file (not JSON)");
  }
  if (!j.is_object() || !j.contains("format") || j["format"] != "l6470emu-coverage")
    throw std::runtime_error("not an l6470emu coverage file (no \"format\": \"l6470emu-coverage\")");
  if (!j.contains("version") || !j["version"].is_number_integer() || j["version"] != kCoverageFormatVersion)
    throw std::runtime_error("coverage format version " +
                             (!j.contains("version")                 ? std::string("missing")
                              : j["version"].is_number_integer() ? j["version"].dump()
                                                                 : quoted_text(j["version"].dump())) +
                             ", this program reads version " + std::to_string(kCoverageFormatVersion));
  if (!j.contains("variants") || !j["variants"].is_object()) throw std::runtime_error("coverage file without \"variants\"");
  auto strings = [](const nlohmann::json& a, const std::string& where) {
    if (!a.is_array()) throw std::runtime_error(where + ": not a list");
    std::set<std::string> out;
    for (const auto& s : a) {
      if (!s.is_string()) throw std::runtime_error(where + ": not a list of names");
      if (s.get_ref<const std::string&>().size() > 200) throw std::runtime_error(where + ": a name longer than any point's");
      out.insert(s.get<std::string>());
    }
    return out;
  };
  CoverageData d;
  for (const auto& [name, v] : j["variants"].items()) {
    // Names from the file are quoted (control characters shown, long ones cut): one line each.
    const CoverageUniverse* u = coverage_universe(name);
    if (!u) throw std::runtime_error("unknown chip variant " + quoted_text(name));
    if (!v.is_object()) throw std::runtime_error(name + ": not an object");
    PerVariant& p = d.variants_[name];
    if (v.contains("chain positions present")) p.positions = strings(v["chain positions present"], name + ": chain positions present");
    for (const std::string& position : p.positions)
      if (!is_chain_position_name(position))
        throw std::runtime_error(name + ": chain positions present: " + quoted_text(position) + " is no \"chip K of N\"");
    if (!v.contains("hit")) continue;
    if (!v["hit"].is_object()) throw std::runtime_error(name + ": \"hit\" is not an object");
    for (const auto& [cat, points] : v["hit"].items()) {
      const CoverageCategory c = coverage_category_named(cat);
      if (c == CoverageCategory::count) throw std::runtime_error(name + ": unknown category " + quoted_text(cat));
      for (const std::string& point : strings(points, name + ": " + cat)) {
        const bool known = c == CoverageCategory::chain_positions ? p.positions.count(point) != 0 : u->find(c, point) >= 0;
        if (!known) throw std::runtime_error(name + ": " + cat + ": unknown point " + quoted_text(point));
        p.hit[static_cast<std::size_t>(c)].insert(point);
      }
    }
  }
  return d;
}

}  // namespace l6470emu
