// A scenario's names and its exchange form (JSON through nlohmann/json, header only).
#include "board/scenario.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>

namespace l6470emu {
namespace {

using nlohmann::json;

template <typename E>
E enum_at(const json& j, const char* key, unsigned count) {
  const unsigned v = j.at(key).get<unsigned>();
  if (v >= count) throw std::out_of_range(std::string("bad ") + key);
  return static_cast<E>(v);
}

// Strings travel as hex: a scenario's names are bytes (a file need not be UTF-8), JSON strings are not.
std::string hex(std::string_view s) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (const unsigned char c : s) {
    out += digits[c >> 4];
    out += digits[c & 15];
  }
  return out;
}
std::string unhex(const json& j) {
  const std::string s = j.get<std::string>();
  if (s.size() % 2) throw std::invalid_argument("odd hex string");
  auto value = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    throw std::invalid_argument("bad hex digit");
  };
  std::string out;
  for (std::size_t i = 0; i < s.size(); i += 2) out += static_cast<char>(value(s[i]) << 4 | value(s[i + 1]));
  return out;
}

json chip_json(const ScenarioChip& c) { return json{{"chain", hex(c.chain)}, {"number", c.number}}; }
ScenarioChip chip_of(const json& j) { return ScenarioChip{unhex(j.at("chain")), j.at("number").get<std::size_t>()}; }

}  // namespace

std::string_view to_string(ScenarioAction::Kind k) {
  constexpr std::string_view n[] = {"sw", "stby_rst", "fault", "load", "block", "supply", "serial", "dir"};
  return n[static_cast<unsigned>(k)];
}
std::string_view to_string(ScenarioTrigger::Kind k) {
  constexpr std::string_view n[] = {"time", "end", "position", "true_position", "busy_fall", "busy_rise", "command"};
  return n[static_cast<unsigned>(k)];
}
std::string_view to_string(ScenarioExpectation::Kind k) {
  constexpr std::string_view n[] = {"register", "true_position", "status", "busy_pulse", "command", "frames", "sanitizer"};
  return n[static_cast<unsigned>(k)];
}

std::string seconds_text(Tick tick) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%llu.%06llu s", static_cast<unsigned long long>(tick / kTicksPerSecond),
                static_cast<unsigned long long>(tick % kTicksPerSecond / 4));
  return buf;
}

std::string serialize_scenario(const Scenario& s) {
  json steps = json::array();
  for (const ScenarioStep& st : s.steps) {
    const ScenarioTrigger& t = st.when;
    json j{{"where", hex(st.where)},
           {"when", {{"kind", static_cast<unsigned>(t.kind)}, {"tick", t.tick}, {"chip", chip_json(t.chip)},
                     {"position", t.position}, {"command", hex(t.command)}, {"count", t.count}, {"delay", t.delay}}}};
    if (st.action) {
      const ScenarioAction& a = *st.action;
      j["do"] = {{"kind", static_cast<unsigned>(a.kind)}, {"chip", chip_json(a.chip)}, {"level", a.level},
                 {"fault", static_cast<unsigned>(a.fault)}, {"value", a.value},
                 {"load", {a.load.inertia_g_mm2, a.load.friction_uNm, a.load.force_uNm}},
                 {"position", a.position}, {"supply_mV", a.supply_mV}, {"text", hex(a.text)}};
    }
    if (st.expect) {
      const ScenarioExpectation& e = *st.expect;
      json flags = json::array();
      for (const auto& [name, bit] : e.flags) flags.push_back({hex(name), bit});
      j["expect"] = {{"kind", static_cast<unsigned>(e.kind)}, {"chip", chip_json(e.chip)}, {"name", hex(e.name)},
                     {"value", e.value}, {"tolerance", e.tolerance}, {"flags", flags}, {"min_ticks", e.min_ticks},
                     {"max_ticks", e.max_ticks}, {"pulse", e.pulse}, {"count", e.count},
                     {"min_count", e.min_count}, {"max_count", e.max_count}};
    }
    steps.push_back(std::move(j));
  }
  json out{{"l6470emu_scenario", 1}, {"name", hex(s.name)}, {"steps", steps}};
  if (s.timeout_ticks) out["timeout_ticks"] = *s.timeout_ticks;
  return out.dump();
}

std::optional<Scenario> deserialize_scenario(std::string_view text, std::string& error) {
  try {
    const json j = json::parse(text);
    if (j.at("l6470emu_scenario").get<int>() != 1) throw std::runtime_error("unknown version");
    Scenario s;
    s.name = unhex(j.at("name"));
    if (j.contains("timeout_ticks")) s.timeout_ticks = j.at("timeout_ticks").get<Tick>();
    for (const json& js : j.at("steps")) {
      ScenarioStep st;
      st.where = unhex(js.at("where"));
      const json& w = js.at("when");
      st.when.kind = enum_at<ScenarioTrigger::Kind>(w, "kind", 7);
      st.when.tick = w.at("tick").get<Tick>();
      st.when.chip = chip_of(w.at("chip"));
      st.when.position = w.at("position").get<std::int64_t>();
      st.when.command = unhex(w.at("command"));
      st.when.count = w.at("count").get<std::uint32_t>();
      st.when.delay = w.at("delay").get<Tick>();
      if (js.contains("do")) {
        const json& a = js.at("do");
        ScenarioAction act;
        act.kind = enum_at<ScenarioAction::Kind>(a, "kind", static_cast<unsigned>(ScenarioAction::Kind::dir) + 1);  // dir: the last
        act.chip = chip_of(a.at("chip"));
        act.level = a.at("level").get<bool>();
        act.fault = enum_at<TraceFault>(a, "fault", kTraceFaultCount);
        act.value = a.at("value").get<std::uint8_t>();
        act.load.inertia_g_mm2 = a.at("load").at(0).get<std::uint32_t>();
        act.load.friction_uNm = a.at("load").at(1).get<std::uint32_t>();
        act.load.force_uNm = a.at("load").at(2).get<std::int32_t>();
        act.position = a.at("position").get<std::int64_t>();
        act.supply_mV = a.at("supply_mV").get<std::uint32_t>();
        if (a.contains("text")) act.text = unhex(a.at("text"));
        st.action = act;
      }
      if (js.contains("expect")) {
        const json& e = js.at("expect");
        ScenarioExpectation x;
        x.kind = enum_at<ScenarioExpectation::Kind>(e, "kind", 7);
        x.chip = chip_of(e.at("chip"));
        x.name = unhex(e.at("name"));
        x.value = e.at("value").get<std::int64_t>();
        x.tolerance = e.at("tolerance").get<std::int64_t>();
        for (const json& f : e.at("flags")) x.flags.emplace_back(unhex(f.at(0)), f.at(1).get<bool>());
        x.min_ticks = e.at("min_ticks").get<Tick>();
        x.max_ticks = e.at("max_ticks").get<Tick>();
        x.pulse = e.at("pulse").get<std::uint32_t>();
        x.count = e.at("count").get<std::uint64_t>();
        x.min_count = e.at("min_count").get<std::uint64_t>();
        x.max_count = e.at("max_count").get<std::uint64_t>();
        st.expect = std::move(x);
      }
      if (st.action.has_value() == st.expect.has_value()) throw std::runtime_error("a step needs an action or an expectation");
      s.steps.push_back(std::move(st));
    }
    return s;
  } catch (const std::exception& e) {
    error = std::string("not a scenario in run's exchange form: ") + e.what();
    return std::nullopt;
  }
}

}  // namespace l6470emu
