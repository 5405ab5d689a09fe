// Parser and writer of the axis clause: decimal numbers are read as exact fixed-point
// integers (no floating point), each item checked against its range.
#include "core/axis_text.hpp"

#include <array>
#include <charconv>
#include <cstdint>
#include <vector>

#include "core/near_miss.hpp"

namespace l6470emu {
namespace {

constexpr std::int64_t kMaxPosition = std::int64_t{1} << 40;

std::int64_t pow10(int d) {
  std::int64_t p = 1;
  while (d-- > 0) p *= 10;
  return p;
}

/// "[-]D[.D]" with at most `decimals` digits after the point, as an integer in 10^-decimals.
bool parse_fixed(std::string_view s, int decimals, bool signed_ok, std::int64_t& out) {
  bool negative = false;
  if (!s.empty() && s[0] == '-' && signed_ok) {
    negative = true;
    s.remove_prefix(1);
  }
  const std::size_t dot = s.find('.');
  const std::string_view whole = s.substr(0, dot);
  const std::string_view frac = dot == std::string_view::npos ? std::string_view{} : s.substr(dot + 1);
  if (whole.empty() && frac.empty()) return false;
  if (dot != std::string_view::npos && frac.empty()) return false;
  if (static_cast<int>(frac.size()) > decimals || whole.size() > 12) return false;
  std::int64_t v = 0;
  for (char c : whole) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  std::int64_t f = 0;
  for (char c : frac) {
    if (c < '0' || c > '9') return false;
    f = f * 10 + (c - '0');
  }
  v = v * pow10(decimals) + f * pow10(decimals - static_cast<int>(frac.size()));
  out = negative ? -v : v;
  return true;
}

std::string fixed_text(std::int64_t v, int decimals) {
  std::string out = v < 0 ? "-" : "";
  const std::uint64_t a = v < 0 ? static_cast<std::uint64_t>(-v) : static_cast<std::uint64_t>(v);
  const std::uint64_t p = static_cast<std::uint64_t>(pow10(decimals));
  out += std::to_string(a / p);
  std::uint64_t f = a % p;
  if (f != 0) {
    std::string digits = std::to_string(f);
    digits.insert(0, static_cast<std::size_t>(decimals) - digits.size(), '0');
    while (digits.back() == '0') digits.pop_back();
    out += "." + digits;
  }
  return out;
}

bool parse_int(std::string_view s, std::int64_t& out) {
  const auto* end = s.data() + s.size();
  auto [p, ec] = std::from_chars(s.data(), end, out, 10);
  return !s.empty() && ec == std::errc{} && p == end;
}

struct Item {
  std::string_view name;
  std::string_view unit;   // shown in errors
  int decimals;
  std::int64_t min, max;   // in 10^-decimals of the unit
  std::int64_t scale;      // model units per 10^-decimals of the unit
  std::int64_t (*get)(const AxisSpec&);
  void (*set)(AxisSpec&, std::int64_t);
};

#define L6470EMU_FIELD(expr, type) \
  [](const AxisSpec& s) -> std::int64_t { return static_cast<std::int64_t>(s.expr); }, \
  [](AxisSpec& s, std::int64_t v) { s.expr = static_cast<type>(v); }

// name, unit, decimals, min, max, scale, field
const std::array<Item, 13> kItems{{
    {"steps", "full steps per revolution, a multiple of 4", 0, 4, 100'000, 1, L6470EMU_FIELD(motor.steps_per_rev, std::uint32_t)},
    {"torque", "N·m holding torque", 6, 1, 1'000'000'000, 1, L6470EMU_FIELD(motor.holding_torque_uNm, std::uint32_t)},
    {"current", "A rated phase current", 3, 1, 100'000, 1, L6470EMU_FIELD(motor.rated_current_mA, std::uint32_t)},
    {"r", "Ω phase resistance", 3, 1, 1'000'000, 1, L6470EMU_FIELD(motor.phase_resistance_mohm, std::uint32_t)},
    {"l", "mH phase inductance", 3, 0, 1'000'000, 1, L6470EMU_FIELD(motor.phase_inductance_uH, std::uint32_t)},
    {"rotor", "g·cm² rotor inertia", 2, 0, 100'000'000, 1, L6470EMU_FIELD(motor.rotor_inertia_g_mm2, std::uint32_t)},
    {"load", "g·cm² load inertia", 2, 0, 1'000'000'000, 1, L6470EMU_FIELD(load.inertia_g_mm2, std::uint32_t)},
    {"friction", "N·m friction", 6, 0, 1'000'000'000, 1, L6470EMU_FIELD(load.friction_uNm, std::uint32_t)},
    {"force", "N·m constant load torque, signed", 6, -1'000'000'000, 1'000'000'000, 1, L6470EMU_FIELD(load.force_uNm, std::int32_t)},
    {"vs", "V motor supply", 3, 1'000, 100'000, 1, L6470EMU_FIELD(supply.supply_mV, std::uint32_t)},
    {"rds", "Ω MOSFET on-resistance", 3, 1, 10'000, 1, L6470EMU_FIELD(supply.rds_on_mohm, std::uint32_t)},
    {"rsense", "Ω sense resistor", 3, 1, 10'000, 1, L6470EMU_FIELD(supply.sense_mohm, std::uint32_t)},
    {"pullin", "step/s pull-in speed", 0, 0, 15'625, 1, L6470EMU_FIELD(pull_in_speed_steps_per_s, std::uint32_t)},
}};

#undef L6470EMU_FIELD

/// Every item name an axis takes, in the order the docs list them.
std::vector<std::string> item_names() {
  std::vector<std::string> names;
  for (const Item& i : kItems) names.emplace_back(i.name);
  for (const char* n : {"stops", "start", "switch"}) names.emplace_back(n);
  return names;
}

std::string item_list() {
  std::string out;
  for (const std::string& n : item_names()) out += (out.empty() ? "" : ", ") + n;
  return out;
}

/// The items closest to a misspelt `word` ("switch" for "swich"), or "".
std::string item_suggestion(std::string_view word) { return closest_names(word, item_names()); }

const Item* find_item(std::string_view name) {
  for (const Item& i : kItems)
    if (i.name == name) return &i;
  return nullptr;
}

std::string range_text(const Item& i) {
  return fixed_text(i.min, i.decimals) + " to " + fixed_text(i.max, i.decimals);
}

std::string quoted(std::string_view s) {
  std::string out = "'";
  for (char c : s.substr(0, 60)) out += (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) ? '?' : c;
  return out + (s.size() > 60 ? "…'" : "'");
}

bool parse_position(std::string_view s, std::int64_t& out) {
  return parse_int(s, out) && out >= -kMaxPosition && out <= kMaxPosition;
}

std::string parse_switch(std::string_view text, SwitchSpec& sw) {
  const std::size_t at = text.find('@');
  if (at == std::string_view::npos || at == 0)
    return "switch=" + quoted(text) + " needs NAME@POSITION (e.g. switch=home@0:below:no:hyst=8)";
  sw.name = std::string(text.substr(0, at));
  for (char c : sw.name)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-'))
      return "switch name " + quoted(sw.name) + " may hold letters, digits, '_' and '-' only";
  std::string_view rest = text.substr(at + 1);
  std::vector<std::string_view> parts;
  for (std::size_t start = 0;;) {
    const std::size_t colon = rest.find(':', start);
    parts.push_back(rest.substr(start, colon == std::string_view::npos ? std::string_view::npos : colon - start));
    if (colon == std::string_view::npos) break;
    start = colon + 1;
  }
  if (!parse_position(parts[0], sw.position))
    return "switch " + sw.name + ": position " + quoted(parts[0]) + " must be a whole number of 1/128 steps within ±2^40";
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const std::string_view p = parts[i];
    std::int64_t v = 0;
    if (p == "below") sw.above = false;
    else if (p == "above") sw.above = true;
    else if (p == "no") sw.normally_closed = false;
    else if (p == "nc") sw.normally_closed = true;
    else if (p.substr(0, 5) == "hyst=") {
      if (!parse_int(p.substr(5), v) || v < 0 || v > (1 << 20))
        return "switch " + sw.name + ": hyst= must be 0 to 1048576 (1/128 steps), not " + quoted(p.substr(5));
      sw.hysteresis = v;
    } else if (p.substr(0, 7) == "bounce=") {
      const std::string_view b = p.substr(7);
      const std::size_t slash = b.find('/');
      std::int64_t count = 0, us = 0;
      if (slash == std::string_view::npos || !parse_int(b.substr(0, slash), count) || !parse_int(b.substr(slash + 1), us) ||
          count < 0 || count > 1000 || us < 1 || us > 1'000'000)
        return "switch " + sw.name + ": bounce= is COUNT/MICROSECONDS (0..1000 reversals, 1..1000000 µs apart), not " +
               quoted(b);
      sw.bounce_count = static_cast<std::uint32_t>(count);
      sw.bounce_ticks = count == 0 ? 0 : static_cast<Tick>(us) * kTicksPerMicrosecond;
    } else {
      return "switch " + sw.name + ": unknown part " + quoted(p) + " (below, above, no, nc, hyst=N, bounce=COUNT/US)";
    }
  }
  return "";
}

std::string parse_items(std::string_view text, AxisSpec& spec, bool load_only) {
  if (text == "default") return "";
  std::vector<std::string_view> seen;
  for (std::size_t start = 0; start <= text.size();) {
    std::size_t comma = text.find(',', start);
    if (comma == std::string_view::npos) comma = text.size();
    const std::string_view item = text.substr(start, comma - start);
    start = comma + 1;
    if (item.empty()) return "empty item (items are NAME=VALUE separated by commas)";
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos || eq == 0) {
      // "swich:100" is a misspelt "switch=..." as often as a missing '='.
      const std::string_view word = item.substr(0, std::min(item.find_first_of(":="), item.size()));
      const std::string near = item_suggestion(word);
      return "item " + quoted(item) + " is not NAME=VALUE" + (near.empty() ? "" : " (did you mean " + near + "=...?)");
    }
    const std::string_view name = item.substr(0, eq), value = item.substr(eq + 1);
    if (value.empty()) return name == "stops" ? "stops= needs LO..HI" : std::string(name) + "= has no value";
    if (name != "switch") {
      for (std::string_view s : seen)
        if (s == name) return std::string(name) + "= is given twice";
      seen.push_back(name);
    }
    const bool load_item = name == "load" || name == "friction" || name == "force";
    if (load_only && !load_item) return "only load=, friction= and force= can change at runtime, not " + std::string(name) + "=";
    if (const Item* it = find_item(name)) {
      std::int64_t v = 0;
      if (!parse_fixed(value, it->decimals, it->min < 0, v) || v < it->min || v > it->max)
        return std::string(name) + "= must be " + range_text(*it) + " (" + std::string(it->unit) +
               (it->decimals ? ", at most " + std::to_string(it->decimals) + " decimals" : "") + "), not " + quoted(value);
      if (name == "steps" && v % 4 != 0) return "steps= must be a multiple of 4 (an electrical cycle is 4 full steps), not " + quoted(value);
      it->set(spec, v * it->scale);
    } else if (name == "stops") {
      const std::size_t dots = value.find("..");
      if (dots == std::string_view::npos) return "stops= is LO..HI in 1/128 steps (either side may be empty), not " + quoted(value);
      const std::string_view lo = value.substr(0, dots), hi = value.substr(dots + 2);
      if (lo.empty() && hi.empty()) return "stops=.. names no stop (write e.g. stops=0..256000 or stops=0..)";
      spec.has_lower_stop = !lo.empty();
      spec.has_upper_stop = !hi.empty();
      if (!lo.empty() && !parse_position(lo, spec.lower_stop))
        return "stops= lower stop " + quoted(lo) + " must be a whole number of 1/128 steps within ±2^40";
      if (!hi.empty() && !parse_position(hi, spec.upper_stop))
        return "stops= upper stop " + quoted(hi) + " must be a whole number of 1/128 steps within ±2^40";
      if (spec.has_lower_stop && spec.has_upper_stop && spec.lower_stop > spec.upper_stop)
        return "stops= " + quoted(value) + ": the lower stop is above the upper one";
    } else if (name == "start") {
      if (!parse_position(value, spec.start_position))
        return "start= must be a whole number of 1/128 steps within ±2^40, not " + quoted(value);
    } else if (name == "switch") {
      if (spec.switches.size() >= 16) return "at most 16 switches per axis";
      SwitchSpec sw;
      if (std::string e = parse_switch(value, sw); !e.empty()) return e;
      spec.switches.push_back(sw);
    } else {
      const std::string near = item_suggestion(name);
      return "unknown item " + quoted(name) + (near.empty() ? "" : ": did you mean " + near + "=?") + " (" + item_list() + ")";
    }
  }
  if ((spec.has_lower_stop && spec.start_position < spec.lower_stop) ||
      (spec.has_upper_stop && spec.start_position > spec.upper_stop))
    return "start=" + std::to_string(spec.start_position) + " lies beyond a hard stop";
  return "";
}

}  // namespace

std::string parse_axis_spec(std::string_view text, AxisSpec& spec) { return parse_items(text, spec, false); }

std::string parse_axis_load(std::string_view text, LoadSpec& load) {
  AxisSpec s;
  s.load = load;
  std::string e = parse_items(text, s, true);
  if (e.empty()) load = s.load;
  return e;
}

std::string describe_axis_spec(const AxisSpec& spec) {
  const AxisSpec defaults;
  std::string out;
  auto add = [&](const std::string& item) { out += (out.empty() ? "" : ",") + item; };
  for (const Item& it : kItems)
    if (it.get(spec) != it.get(defaults)) add(std::string(it.name) + "=" + fixed_text(it.get(spec) / it.scale, it.decimals));
  if (spec.has_lower_stop || spec.has_upper_stop)
    add("stops=" + (spec.has_lower_stop ? std::to_string(spec.lower_stop) : "") + ".." +
        (spec.has_upper_stop ? std::to_string(spec.upper_stop) : ""));
  if (spec.start_position != 0) add("start=" + std::to_string(spec.start_position));
  for (const SwitchSpec& sw : spec.switches) {
    std::string s = "switch=" + sw.name + "@" + std::to_string(sw.position) + (sw.above ? ":above" : ":below") +
                    (sw.normally_closed ? ":nc" : ":no");
    if (sw.hysteresis) s += ":hyst=" + std::to_string(sw.hysteresis);
    if (sw.bounce_count) s += ":bounce=" + std::to_string(sw.bounce_count) + "/" + std::to_string(sw.bounce_ticks / kTicksPerMicrosecond);
    add(s);
  }
  return out;
}

}  // namespace l6470emu
