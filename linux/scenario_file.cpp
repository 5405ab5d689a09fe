// Scenario files: YAML through yaml-cpp, checked key by key against docs/scenarios.md's schema.
#include "linux/scenario_file.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "board/board_config.hpp"
#include "spi/input_file.hpp"

namespace l6470emu {
namespace {

// One line of error, thrown through the reader and caught at the top.
struct Bad : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::size_t edit_distance(std::string_view a_in, std::string_view b_in) {
  const std::string a = lower(a_in), b = lower(b_in);
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// " (did you mean A or B?)" for the candidates at most 2 edits from `word`, or "".
std::string near_miss(std::string_view word, const std::vector<std::string>& candidates) {
  if (word.empty() || word.size() > 32) return "";
  std::size_t best = 3;
  std::vector<std::string> hits;
  for (const auto& c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (d >= word.size() || d > best) continue;
    if (d < best) hits.clear();
    best = d;
    hits.push_back(c);
  }
  if (hits.empty()) return "";
  std::string out = " (did you mean ";
  for (std::size_t i = 0; i < hits.size(); ++i) out += (i == 0 ? "" : i + 1 == hits.size() ? " or " : ", ") + hits[i];
  return out + "?)";
}

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  Scenario read(const YAML::Node& root) {
    Scenario s;
    if (!root.IsDefined() || root.IsNull()) fail(root, "", "the file is empty: a scenario needs steps:");
    if (!root.IsMap()) fail(root, "", "a scenario is a map with steps: (and optionally name:, timeout:)");
    check_keys(root, "", {"name", "timeout", "steps"});
    if (const YAML::Node n = root["name"]) s.name = scalar(n, "name");
    if (const YAML::Node t = root["timeout"]) {
      s.timeout_ticks = duration(t, "timeout");
      if (*s.timeout_ticks == 0) fail(t, "timeout", "0 is no time limit a run can have (leave timeout: out for none)");
    }
    const YAML::Node steps = root["steps"];
    if (!steps) fail(root, "steps", "missing: a scenario needs a list of steps");
    if (!steps.IsSequence()) fail(steps, "steps", "expects a list of steps (each line starting with '- ')");
    for (const YAML::Node& st : steps) s.steps.push_back(step(st));
    return s;
  }

 private:
  [[noreturn]] void fail(const YAML::Node& n, std::string_view key, const std::string& what) const {
    const YAML::Mark m = n.Mark();
    std::string where = "l6470emu: scenario " + file_;
    if (m.line >= 0) where += ":" + std::to_string(m.line + 1);
    throw Bad(where + ": " + (key.empty() ? "" : "key '" + shown_text(key) + "': ") + what);
  }

  std::string where_of(const YAML::Node& n) const {
    return file_ + ":" + std::to_string(n.Mark().line >= 0 ? n.Mark().line + 1 : 0);
  }

  void check_keys(const YAML::Node& map, std::string_view in, const std::vector<std::string>& allowed) const {
    std::set<std::string> seen;
    for (const auto& kv : map) {
      if (!kv.first.IsScalar()) fail(kv.first, in, "keys are words");
      const std::string k = kv.first.Scalar();
      if (std::find(allowed.begin(), allowed.end(), k) == allowed.end()) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        fail(kv.first, k, "unknown" + near_miss(k, allowed) + (in.empty() ? "" : " in " + std::string(in)) +
                                           "; known: " + list);
      }
      if (!seen.insert(k).second) fail(kv.first, k, "given twice");
    }
  }

  std::string scalar(const YAML::Node& n, std::string_view key) const {
    if (!n.IsScalar()) fail(n, key, "expects a single value");
    return n.Scalar();
  }

  std::int64_t integer(const YAML::Node& n, std::string_view key, std::int64_t lo, std::int64_t hi) const {
    const std::string s = scalar(n, key);
    std::int64_t v = 0;
    std::size_t used = 0;
    try {
      const bool neg = !s.empty() && s[0] == '-';
      const std::string body = neg || (!s.empty() && s[0] == '+') ? s.substr(1) : s;
      const bool hex = body.size() > 2 && body[0] == '0' && (body[1] == 'x' || body[1] == 'X');
      if (body.empty() || body[0] == '-' || body[0] == '+' || std::isspace(static_cast<unsigned char>(body[0])))
        throw std::invalid_argument("");
      const unsigned long long u = std::stoull(hex ? body.substr(2) : body, &used, hex ? 16 : 10);
      if (used != body.size() - (hex ? 2 : 0)) throw std::invalid_argument("");
      if (u > static_cast<unsigned long long>(std::numeric_limits<std::int64_t>::max())) throw std::out_of_range("");
      v = neg ? -static_cast<std::int64_t>(u) : static_cast<std::int64_t>(u);
    } catch (const std::exception&) {
      fail(n, key, "expects a whole number, got " + quoted_text(s));
    }
    if (v < lo || v > hi)
      fail(n, key, std::to_string(v) + " is out of range (" + std::to_string(lo) + ".." + std::to_string(hi) + ")");
    return v;
  }

  Tick duration(const YAML::Node& n, std::string_view key) const {
    const std::string s = scalar(n, key);
    const auto t = parse_scenario_duration(s);
    if (!t) fail(n, key, "expects a duration (250ns, 1us, 10ms, 2.5s, 1min: whole ticks of 250 ns), got " + quoted_text(s));
    return *t;
  }

  bool flag(const YAML::Node& n, std::string_view key) const {
    const std::string s = lower(scalar(n, key));
    if (s == "true" || s == "yes" || s == "1") return true;
    if (s == "false" || s == "no" || s == "0") return false;
    fail(n, key, "expects true or false, got " + quoted_text(s));
  }

  std::string choice(const YAML::Node& n, std::string_view key, const std::vector<std::string>& choices) const {
    const std::string s = scalar(n, key);
    for (const auto& c : choices)
      if (lower(c) == lower(s)) return c;
    std::string list;
    for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
    fail(n, key, quoted_text(s) + " is not one of " + list + near_miss(s, choices));
  }

  // chain:/chip: of `map`, defaulting to the step's.
  ScenarioChip chip_of(const YAML::Node& map, const ScenarioChip& dflt) const {
    ScenarioChip c = dflt;
    if (const YAML::Node n = map["chain"]) c.chain = scalar(n, "chain");
    if (const YAML::Node n = map["chip"]) c.number = static_cast<std::size_t>(integer(n, "chip", 0, 1'000'000));
    return c;
  }

  ScenarioStep step(const YAML::Node& n) {
    if (!n.IsMap()) fail(n, "steps", "each step is a map (at: or on:, then do: or expect:)");
    check_keys(n, "a step", {"at", "on", "after", "delay", "chip", "chain", "do", "expect"});
    ScenarioStep st;
    st.where = where_of(n);
    const ScenarioChip dflt = chip_of(n, ScenarioChip{});
    const YAML::Node at = n["at"], on = n["on"];
    if (at && on) fail(on, "on", "a step has either at: or on:, not both");
    if (!at && !on) fail(n, "", "a step needs at: (a time or end) or on: (an event)");
    if (at) {
      if (n["after"]) fail(n["after"], "after", "only for on: (events); at: is already a time");
      if (n["delay"]) fail(n["delay"], "delay", "only for on: (events); at: is already a time");
      if (at.IsScalar() && lower(at.Scalar()) == "end")
        st.when.kind = ScenarioTrigger::Kind::end;
      else
        st.when.tick = duration(at, "at");
    } else {
      if (!on.IsMap()) fail(on, "on", "expects a map: {position: N} {true_position: N} {busy: fall|rise} {command: NAME}");
      check_keys(on, "on:", {"position", "true_position", "busy", "command", "count", "chip", "chain"});
      st.when.chip = chip_of(on, dflt);
      int kinds = 0;
      if (const YAML::Node p = on["position"]) {
        ++kinds;
        st.when.kind = ScenarioTrigger::Kind::position;
        st.when.position = integer(p, "position", -(1 << 21), (1 << 21) - 1);
      }
      if (const YAML::Node p = on["true_position"]) {
        ++kinds;
        st.when.kind = ScenarioTrigger::Kind::true_position;
        st.when.position = integer(p, "true_position", -(std::int64_t{1} << 40), std::int64_t{1} << 40);
      }
      if (const YAML::Node b = on["busy"]) {
        ++kinds;
        st.when.kind = choice(b, "busy", {"fall", "rise"}) == "fall" ? ScenarioTrigger::Kind::busy_fall
                                                                      : ScenarioTrigger::Kind::busy_rise;
      }
      if (const YAML::Node c = on["command"]) {
        ++kinds;
        st.when.kind = ScenarioTrigger::Kind::command;
        st.when.command = scalar(c, "command");
      }
      if (kinds != 1) fail(on, "on", "names exactly one event: position, true_position, busy or command");
      if (const YAML::Node c = on["count"]) st.when.count = static_cast<std::uint32_t>(integer(c, "count", 1, 1'000'000'000));
      if (const YAML::Node a = n["after"]) st.when.tick = duration(a, "after");
      if (const YAML::Node d = n["delay"]) st.when.delay = duration(d, "delay");
    }
    const YAML::Node act = n["do"], exp = n["expect"];
    if (act && exp) fail(exp, "expect", "a step has either do: or expect:, not both");
    if (!act && !exp) fail(n, "", "a step needs do: (an action) or expect: (an expectation)");
    if (act) {
      if (st.when.kind == ScenarioTrigger::Kind::end) fail(act, "do", "nothing can be done at the end; use expect:");
      st.action = action(act, dflt);
    } else {
      st.expect = expectation(exp, dflt);
      if (st.expect->kind == ScenarioExpectation::Kind::busy_pulse && st.when.kind != ScenarioTrigger::Kind::end)
        fail(exp, "busy_pulse", "BUSY pulses are judged at the end: write at: end");
    }
    return st;
  }

  ScenarioAction action(const YAML::Node& m, const ScenarioChip& dflt) {
    if (!m.IsMap()) fail(m, "do", "expects a map such as {sw: close}");
    const std::vector<std::string> kinds{"sw", "stby_rst", "dir", "fault", "thermal", "adcin", "load", "block", "supply_mV", "serial"};
    std::vector<std::string> keys = kinds;
    keys.insert(keys.end(), {"clear", "bit", "chip", "chain"});
    check_keys(m, "do:", keys);
    ScenarioAction a;
    a.chip = chip_of(m, dflt);
    int n = 0;
    for (const auto& k : kinds) n += m[k] ? 1 : 0;
    if (n != 1) fail(m, "do", "names exactly one action: sw, stby_rst, dir, fault, thermal, adcin, load, block, supply_mV or serial");
    if (const YAML::Node v = m["serial"]) {
      // Text typed into the program's Serial: no chip takes it.
      for (const char* k : {"chip", "chain"})
        if (m[k]) fail(m[k], k, "not with serial: (the text goes to the program's Serial, not to a chip)");
      a.kind = ScenarioAction::Kind::serial;
      a.text = scalar(v, "serial");
      if (a.text.empty()) fail(v, "serial", "types nothing: give the text, e.g. \"G 100\\n\"");
      return a;
    }
    if (m["clear"] && !m["fault"]) fail(m["clear"], "clear", "only with fault:");
    if (m["bit"] && !m["fault"]) fail(m["bit"], "bit", "only with fault: miso_flip");
    if (const YAML::Node v = m["sw"]) {
      a.kind = ScenarioAction::Kind::sw;
      a.level = choice(v, "sw", {"close", "open"}) == "open";
    } else if (const YAML::Node v = m["stby_rst"]) {
      a.kind = ScenarioAction::Kind::stby_rst;
      a.level = choice(v, "stby_rst", {"low", "high"}) == "high";
    } else if (const YAML::Node v = m["dir"]) {
      a.kind = ScenarioAction::Kind::dir;
      a.level = choice(v, "dir", {"low", "high"}) == "high";
    } else if (const YAML::Node v = m["fault"]) {
      a.kind = ScenarioAction::Kind::fault;
      const std::string f =
          choice(v, "fault", {"ocd", "uvlo", "uvlo_adc", "stall_a", "stall_b", "reset", "miso_flip", "lost_frame"});
      if (f == "reset" || f == "miso_flip" || f == "lost_frame") {
        // One-shot events: nothing to clear.
        if (m["clear"]) fail(m["clear"], "clear", "not with fault: " + f + " (it happens once: nothing to clear)");
        if (m["bit"] && f != "miso_flip") fail(m["bit"], "bit", "only with fault: miso_flip");
        a.fault = f == "reset" ? TraceFault::POWER_CYCLE : f == "miso_flip" ? TraceFault::MISO_FLIP : TraceFault::LOST_FRAME;
        a.value = f == "miso_flip" ? static_cast<std::uint8_t>(m["bit"] ? integer(m["bit"], "bit", 0, 7) : 7) : 0;
      } else {
        if (m["bit"]) fail(m["bit"], "bit", "only with fault: miso_flip");
        a.fault = f == "ocd" ? TraceFault::OCD : f == "uvlo" ? TraceFault::UVLO : f == "uvlo_adc" ? TraceFault::UVLO_ADC
                  : f == "stall_a" ? TraceFault::STALL_A : TraceFault::STALL_B;
        a.value = m["clear"] && flag(m["clear"], "clear") ? 0 : 1;
      }
    } else if (const YAML::Node v = m["thermal"]) {
      a.kind = ScenarioAction::Kind::fault;
      a.fault = TraceFault::THERMAL;
      const std::vector<std::string> classes{"normal", "warning", "bridge_shutdown", "device_shutdown"};
      const std::string c = choice(v, "thermal", classes);
      a.value = static_cast<std::uint8_t>(std::find(classes.begin(), classes.end(), c) - classes.begin());
    } else if (const YAML::Node v = m["adcin"]) {
      a.kind = ScenarioAction::Kind::fault;
      a.fault = TraceFault::ADCIN;
      a.value = static_cast<std::uint8_t>(integer(v, "adcin", 0, 31));
    } else if (const YAML::Node v = m["load"]) {
      a.kind = ScenarioAction::Kind::load;
      if (!v.IsMap()) fail(v, "load", "expects a map: {inertia_g_mm2: N, friction_uNm: N, force_uNm: N}");
      check_keys(v, "load:", {"inertia_g_mm2", "friction_uNm", "force_uNm"});
      if (const YAML::Node x = v["inertia_g_mm2"]) a.load.inertia_g_mm2 = static_cast<std::uint32_t>(integer(x, "inertia_g_mm2", 0, 100'000'000));
      if (const YAML::Node x = v["friction_uNm"]) a.load.friction_uNm = static_cast<std::uint32_t>(integer(x, "friction_uNm", 0, 1'000'000'000));
      if (const YAML::Node x = v["force_uNm"]) a.load.force_uNm = static_cast<std::int32_t>(integer(x, "force_uNm", -1'000'000'000, 1'000'000'000));
    } else if (const YAML::Node v = m["block"]) {
      a.kind = ScenarioAction::Kind::block;
      a.position = integer(v, "block", -(std::int64_t{1} << 40), std::int64_t{1} << 40);
    } else if (const YAML::Node v = m["supply_mV"]) {
      a.kind = ScenarioAction::Kind::supply;
      a.supply_mV = static_cast<std::uint32_t>(integer(v, "supply_mV", 0, 100'000));
    }
    return a;
  }

  ScenarioExpectation expectation(const YAML::Node& m, const ScenarioChip& dflt) {
    if (!m.IsMap()) fail(m, "expect", "expects a map such as {register: ABS_POS, value: 0}");
    const std::vector<std::string> kinds{"register", "true_position", "status", "busy_pulse", "command", "frames", "sanitizer"};
    std::vector<std::string> keys = kinds;
    keys.insert(keys.end(), {"value", "tolerance", "sent", "count", "chip", "chain"});
    check_keys(m, "expect:", keys);
    ScenarioExpectation e;
    e.chip = chip_of(m, dflt);
    int n = 0;
    for (const auto& k : kinds) n += m[k] ? 1 : 0;
    if (n != 1) fail(m, "expect", "names exactly one of register, true_position, status, busy_pulse, command, frames, sanitizer");
    auto only = [&](std::initializer_list<const char*> allowed, const char* what) {
      for (const char* k : {"value", "tolerance", "sent", "count"}) {
        if (!m[k]) continue;
        bool ok = false;
        for (const char* a : allowed) ok = ok || std::string_view(a) == k;
        if (!ok) fail(m[k], k, std::string("does not go with ") + what);
      }
    };
    auto tolerance = [&] {
      if (const YAML::Node t = m["tolerance"]) e.tolerance = integer(t, "tolerance", 0, std::int64_t{1} << 40);
    };
    if (const YAML::Node v = m["register"]) {
      only({"value", "tolerance"}, "register");
      e.kind = ScenarioExpectation::Kind::reg;
      e.name = scalar(v, "register");
      if (!m["value"]) fail(m, "value", "missing: register: needs value:");
      e.value = integer(m["value"], "value", -(std::int64_t{1} << 32), std::int64_t{1} << 32);
      tolerance();
    } else if (const YAML::Node v = m["true_position"]) {
      only({"tolerance"}, "true_position");
      e.kind = ScenarioExpectation::Kind::true_position;
      e.value = integer(v, "true_position", -(std::int64_t{1} << 40), std::int64_t{1} << 40);
      tolerance();
    } else if (const YAML::Node v = m["status"]) {
      only({}, "status");
      e.kind = ScenarioExpectation::Kind::status;
      if (!v.IsMap() || v.size() == 0) fail(v, "status", "expects a map of flags and bits, such as {OCD: 0, UVLO: 1}");
      for (const auto& kv : v) {
        const std::string name = scalar(kv.first, "status");
        e.flags.emplace_back(name, integer(kv.second, name, 0, 1) == 1);
      }
    } else if (const YAML::Node v = m["busy_pulse"]) {
      only({}, "busy_pulse");
      e.kind = ScenarioExpectation::Kind::busy_pulse;
      if (!v.IsMap()) fail(v, "busy_pulse", "expects a map: {min: DURATION, max: DURATION, pulse: N}");
      check_keys(v, "busy_pulse:", {"min", "max", "pulse"});
      if (const YAML::Node x = v["min"]) e.min_ticks = duration(x, "min");
      if (const YAML::Node x = v["max"]) e.max_ticks = duration(x, "max");
      if (const YAML::Node x = v["pulse"]) e.pulse = static_cast<std::uint32_t>(integer(x, "pulse", 1, 1'000'000'000));
      if (e.min_ticks > e.max_ticks) fail(v, "busy_pulse", "min is longer than max");
    } else if (const YAML::Node v = m["command"]) {
      only({"sent", "count"}, "command");
      e.kind = ScenarioExpectation::Kind::command;
      e.name = scalar(v, "command");
      if (m["sent"] && m["count"]) fail(m["count"], "count", "give sent: or count:, not both");
      if (const YAML::Node s = m["sent"]) e.count = flag(s, "sent") ? ScenarioExpectation::kAtLeastOnce : 0;
      if (const YAML::Node c = m["count"]) e.count = static_cast<std::uint64_t>(integer(c, "count", 0, std::int64_t{1} << 53));
    } else if (const YAML::Node v = m["sanitizer"]) {
      only({}, "sanitizer");
      e.kind = ScenarioExpectation::Kind::sanitizer;
      if (scalar(v, "sanitizer") != "clean") fail(v, "sanitizer", "takes clean (no rule of the chip broken)");
    } else if (const YAML::Node v = m["frames"]) {
      only({}, "frames");
      e.kind = ScenarioExpectation::Kind::frames;
      if (v.IsMap()) {
        check_keys(v, "frames:", {"min", "max"});
        if (const YAML::Node x = v["min"]) e.min_count = static_cast<std::uint64_t>(integer(x, "min", 0, std::int64_t{1} << 53));
        if (const YAML::Node x = v["max"]) e.max_count = static_cast<std::uint64_t>(integer(x, "max", 0, std::int64_t{1} << 53));
        if (e.min_count > e.max_count) fail(v, "frames", "min is more than max");
      } else {
        e.min_count = e.max_count = static_cast<std::uint64_t>(integer(v, "frames", 0, std::int64_t{1} << 53));
      }
    }
    return e;
  }

  std::string file_;
};

// The deepest nesting a scenario needs is 5; the YAML library recurses per level, so anything
// much deeper is refused before it sees the text.
constexpr int kMaxNesting = 32;

// The line where flow brackets or indentation first nest deeper than kMaxNesting levels, or 0.
std::size_t too_deep(std::string_view text) {
  int depth = 0;
  std::size_t line = 1;
  bool in_single = false, in_double = false, comment = false, line_start = true;
  std::size_t indent = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      comment = false;
      line_start = true;
      indent = 0;
      continue;
    }
    if (line_start) {
      if (c == ' ' || c == '-') {
        if (++indent > 4 * kMaxNesting) return line;
        continue;
      }
      line_start = false;
    }
    if (comment) continue;
    if (in_double) {
      if (c == '\\') ++i;
      else if (c == '"') in_double = false;
      continue;
    }
    if (in_single) {
      if (c == '\'') in_single = false;
      continue;
    }
    if (c == '#') comment = true;
    else if (c == '"') in_double = true;
    else if (c == '\'') in_single = true;
    else if (c == '[' || c == '{') {
      if (++depth > kMaxNesting) return line;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return 0;
}

// The line where a second YAML document starts, or 0. Document markers stand at the start of a
// line ('---' or '...' followed by a blank or the line's end) and cannot occur inside a scalar; a
// '---' before any content only opens the first document, and a '...' may end the last.
std::size_t second_document(std::string_view text) {
  bool content = false, opened = false, ended = false;
  std::size_t line = 0;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t nl = std::min(text.find('\n', at), text.size());
    std::string_view l = text.substr(at, nl - at);
    at = nl + 1;
    ++line;
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    const auto marker = [&](std::string_view m) {
      return l.substr(0, 3) == m && (l.size() == 3 || l[3] == ' ' || l[3] == '\t');
    };
    std::size_t first = 0;
    while (first < l.size() && (l[first] == ' ' || l[first] == '\t')) ++first;
    const bool blank = first == l.size() || l[first] == '#';
    if (marker("---")) {
      if (content || opened || ended) return line;
      opened = true;
      const std::string_view rest = l.substr(3);
      if (rest.find_first_not_of(" \t") != std::string_view::npos && rest[rest.find_first_not_of(" \t")] != '#')
        content = true;  // '--- value' on the marker's line
    } else if (marker("...")) {
      ended = true;
    } else if (!blank && l[0] != '%') {
      if (ended) return line;
      content = true;
    }
  }
  return 0;
}

}  // namespace

std::optional<Tick> parse_scenario_duration(std::string_view text) {
  std::string s(text);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  std::size_t i = 0;
  std::uint64_t whole = 0, frac = 0, frac_scale = 1;
  bool digits = false;
  for (; i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])); ++i) {
    if (whole > 1'000'000'000'000ull) return std::nullopt;
    whole = whole * 10 + static_cast<unsigned>(s[i] - '0');
    digits = true;
  }
  if (i < s.size() && s[i] == '.') {
    for (++i; i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])); ++i) {
      if (frac_scale >= 1'000'000'000'000ull) return std::nullopt;
      frac = frac * 10 + static_cast<unsigned>(s[i] - '0');
      frac_scale *= 10;
      digits = true;
    }
  }
  if (!digits) return std::nullopt;
  std::string unit = s.substr(i);
  while (!unit.empty() && unit.front() == ' ') unit.erase(unit.begin());
  // ns per unit
  std::uint64_t ns;
  if (unit == "ns") ns = 1;
  else if (unit == "us" || unit == "µs") ns = 1'000;
  else if (unit == "ms") ns = 1'000'000;
  else if (unit == "s" || unit.empty()) ns = 1'000'000'000;
  else if (unit == "min") ns = 60'000'000'000ull;
  else return std::nullopt;
  // whole × ns + frac × ns / frac_scale, exactly, in ns; then whole ticks of 250 ns.
  const unsigned __int128 total = static_cast<unsigned __int128>(whole) * ns * frac_scale + static_cast<unsigned __int128>(frac) * ns;
  if (total % frac_scale != 0) return std::nullopt;
  const unsigned __int128 total_ns = total / frac_scale;
  if (total_ns % 250 != 0) return std::nullopt;
  const unsigned __int128 ticks = total_ns / 250;
  if (ticks >= static_cast<unsigned __int128>(kNever)) return std::nullopt;
  return static_cast<Tick>(ticks);
}

ScenarioParse parse_scenario_yaml(std::string_view text, std::string_view file) {
  ScenarioParse out;
  const std::string name = shown_text(file, 200);
  if (text.size() > kMaxScenarioBytes) {
    out.error = "l6470emu: scenario " + name + ": longer than " + std::to_string(kMaxScenarioBytes) + " bytes";
    return out;
  }
  if (const std::size_t line = too_deep(text)) {
    out.error = "l6470emu: scenario " + name + ":" + std::to_string(line) + ": nested deeper than a scenario can be";
    return out;
  }
  try {
    // A second document would be left out without a word by the YAML library's Load (and read
    // whole, however large, by its LoadAll): it is found in the text and refused.
    if (const std::size_t line = second_document(text))
      throw Bad("l6470emu: scenario " + name + ":" + std::to_string(line) +
                ": a second YAML document (after '---' or '...'): a scenario file holds one");
    const YAML::Node root = YAML::Load(std::string(text));
    out.scenario = Reader(name).read(root);
    if (out.scenario->name.empty()) {
      const std::string f(file);
      out.scenario->name = f.substr(f.rfind('/') == std::string::npos ? 0 : f.rfind('/') + 1);
    }
  } catch (const Bad& e) {
    out.error = e.what();
  } catch (const YAML::Exception& e) {
    out.error = "l6470emu: scenario " + name + ":" + std::to_string(e.mark.line + 1) + ": not YAML: " + shown_text(e.msg, 200);
  } catch (const std::exception& e) {
    out.error = "l6470emu: scenario " + name + ": " + shown_text(e.what(), 200);
  }
  if (!out.error.empty()) out.scenario.reset();
  return out;
}

ScenarioParse load_scenario_file(const std::string& path) {
  // A device, a directory or a FIFO nobody writes to is refused (spi/input_file.hpp); at most
  // kMaxScenarioBytes + 1 bytes are read, and the parser says when that is too many.
  std::string why;
  const std::optional<std::string> text = read_input_file(path, kMaxScenarioBytes, why);
  if (!text) {
    ScenarioParse out;
    out.error = "l6470emu: scenario " + shown_text(path, 200) + ": " + why;
    return out;
  }
  return parse_scenario_yaml(*text, path);
}

}  // namespace l6470emu
