// Scenario files written back: one step per list item, every value in the form the reader takes.
#include "linux/scenario_yaml.hpp"

#include <cstdio>
#include <sstream>

namespace l6470emu {
namespace {

// A YAML double-quoted scalar: any UTF-8 text, escaped so that the reader gets it back as it was.
// Bytes that are not UTF-8 cannot be said in YAML at all: they are written as they are, and the
// file may not read.
std::string quoted(std::string_view s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

std::string chip_keys(const ScenarioChip& c) {
  std::string out = "chip: " + std::to_string(c.number);
  if (!c.chain.empty()) out += ", chain: " + quoted(c.chain);
  return out;
}

std::string_view fault_word(TraceFault f) {
  switch (f) {
    case TraceFault::OCD: return "ocd";
    case TraceFault::UVLO: return "uvlo";
    case TraceFault::UVLO_ADC: return "uvlo_adc";
    case TraceFault::STALL_A: return "stall_a";
    case TraceFault::STALL_B: return "stall_b";
    case TraceFault::POWER_CYCLE: return "reset";
    case TraceFault::MISO_FLIP: return "miso_flip";
    case TraceFault::LOST_FRAME: return "lost_frame";
    default: return "";
  }
}

std::string action_text(const ScenarioAction& a) {
  if (a.kind == ScenarioAction::Kind::serial) return "{serial: " + quoted(a.text) + "}";  // no chip
  std::ostringstream o;
  o << "{";
  switch (a.kind) {
    case ScenarioAction::Kind::sw: o << "sw: " << (a.level ? "open" : "close"); break;
    case ScenarioAction::Kind::stby_rst: o << "stby_rst: " << (a.level ? "high" : "low"); break;
    case ScenarioAction::Kind::dir: o << "dir: " << (a.level ? "high" : "low"); break;
    case ScenarioAction::Kind::fault:
      if (a.fault == TraceFault::THERMAL)
        o << "thermal: " << thermal_name(a.value);
      else if (a.fault == TraceFault::ADCIN)
        o << "adcin: " << unsigned{a.value};
      else if (a.fault == TraceFault::MISO_FLIP)
        o << "fault: miso_flip, bit: " << unsigned{a.value};
      else if (a.fault == TraceFault::POWER_CYCLE || a.fault == TraceFault::LOST_FRAME)
        o << "fault: " << fault_word(a.fault);
      else
        o << "fault: " << fault_word(a.fault) << (a.value == 0 ? ", clear: true" : "");
      break;
    case ScenarioAction::Kind::load:
      o << "load: {inertia_g_mm2: " << a.load.inertia_g_mm2 << ", friction_uNm: " << a.load.friction_uNm
        << ", force_uNm: " << a.load.force_uNm << "}";
      break;
    case ScenarioAction::Kind::block: o << "block: " << a.position; break;
    case ScenarioAction::Kind::supply: o << "supply_mV: " << a.supply_mV; break;
    case ScenarioAction::Kind::serial: break;  // written above
  }
  o << ", " << chip_keys(a.chip) << "}";
  return o.str();
}

std::string expectation_text(const ScenarioExpectation& e) {
  std::ostringstream o;
  o << "{";
  switch (e.kind) {
    case ScenarioExpectation::Kind::reg:
      o << "register: " << quoted(e.name) << ", value: " << e.value;
      if (e.tolerance) o << ", tolerance: " << e.tolerance;
      break;
    case ScenarioExpectation::Kind::true_position:
      o << "true_position: " << e.value;
      if (e.tolerance) o << ", tolerance: " << e.tolerance;
      break;
    case ScenarioExpectation::Kind::status: {
      o << "status: {";
      bool first = true;
      for (const auto& [flag, bit] : e.flags) {
        o << (first ? "" : ", ") << quoted(flag) << ": " << (bit ? 1 : 0);
        first = false;
      }
      o << "}";
      break;
    }
    case ScenarioExpectation::Kind::busy_pulse:
      o << "busy_pulse: {min: " << scenario_duration_text(e.min_ticks);
      if (e.max_ticks != kNever) o << ", max: " << scenario_duration_text(e.max_ticks);
      if (e.pulse) o << ", pulse: " << e.pulse;
      o << "}";
      break;
    case ScenarioExpectation::Kind::command:
      o << "command: " << quoted(e.name) << ", ";
      if (e.count == ScenarioExpectation::kAtLeastOnce) o << "sent: true";
      else o << "count: " << e.count;
      break;
    case ScenarioExpectation::Kind::frames:
      o << "frames: {min: " << e.min_count;
      if (e.max_count != UINT64_MAX) o << ", max: " << e.max_count;
      o << "}";
      break;
    case ScenarioExpectation::Kind::sanitizer: o << "sanitizer: clean"; break;
  }
  o << ", " << chip_keys(e.chip) << "}";
  return o.str();
}

}  // namespace

std::string scenario_duration_text(Tick ticks) {
  // One tick is 0.00000025 s: seconds and 8 decimals say every tick count exactly.
  const Tick whole = ticks / kTicksPerSecond;
  std::string frac = std::to_string((ticks % kTicksPerSecond) * 25);
  std::string out = std::to_string(whole);
  if (frac != "0") {
    frac = std::string(8 - frac.size(), '0') + frac;
    while (frac.back() == '0') frac.pop_back();
    out += "." + frac;
  }
  return out + "s";
}

std::string scenario_yaml(const Scenario& s, std::string_view comments) {
  std::ostringstream o;
  for (std::size_t at = 0; at < comments.size();) {
    const std::size_t nl = std::min(comments.find('\n', at), comments.size());
    o << "# " << comments.substr(at, nl - at) << "\n";
    at = nl + 1;
  }
  if (!s.name.empty()) o << "name: " << quoted(s.name) << "\n";
  if (s.timeout_ticks) o << "timeout: " << scenario_duration_text(*s.timeout_ticks) << "\n";
  o << "steps:" << (s.steps.empty() ? " []" : "") << "\n";
  for (const ScenarioStep& st : s.steps) {
    if (!st.where.empty()) o << "  # " << st.where << "\n";
    const ScenarioTrigger& w = st.when;
    switch (w.kind) {
      case ScenarioTrigger::Kind::time: o << "  - at: " << scenario_duration_text(w.tick) << "\n"; break;
      case ScenarioTrigger::Kind::end: o << "  - at: end\n"; break;
      default: {
        o << "  - on: {";
        switch (w.kind) {
          case ScenarioTrigger::Kind::position: o << "position: " << w.position; break;
          case ScenarioTrigger::Kind::true_position: o << "true_position: " << w.position; break;
          case ScenarioTrigger::Kind::busy_fall: o << "busy: fall"; break;
          case ScenarioTrigger::Kind::busy_rise: o << "busy: rise"; break;
          case ScenarioTrigger::Kind::command: o << "command: " << quoted(w.command); break;
          default: break;
        }
        o << ", count: " << w.count << ", " << chip_keys(w.chip) << "}\n";
        if (w.tick) o << "    after: " << scenario_duration_text(w.tick) << "\n";
        if (w.delay) o << "    delay: " << scenario_duration_text(w.delay) << "\n";
      }
    }
    if (st.action) o << "    do: " << action_text(*st.action) << "\n";
    if (st.expect) o << "    expect: " << expectation_text(*st.expect) << "\n";
  }
  return o.str();
}

}  // namespace l6470emu
