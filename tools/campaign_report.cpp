// Campaign reports: verdicts from run's outcome, JSON through nlohmann-json (ordered keys), the
// JUnit XML and the printed matrix.
#include "tools/campaign_report.hpp"

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/near_miss.hpp"
#include "board/run_report.hpp"
#include "tools/campaign_plan.hpp"
#include "tools/xml_text.hpp"

namespace l6470emu {
namespace {

using Json = nlohmann::ordered_json;
constexpr const char* kFormat = "l6470emu-campaign/1";

std::string xml(std::string_view s) { return xml_text(s); }

std::string seconds(Tick t) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6f", static_cast<double>(t) / static_cast<double>(kTicksPerSecond));
  return buf;
}

Json rerun_json(const RerunResult& r) {
  Json j;
  j["index"] = r.index;
  j["fault"] = r.fault;
  j["chain"] = r.chain;
  j["chip"] = r.chip;
  j["point"] = {{"name", r.point}, {"tick", r.tick}, {"seconds", seconds(r.tick)}, {"after_command", r.after_command}};
  j["verdict"] = std::string(to_string(r.verdict));
  j["flag_read"] = r.flag_read ? Json(*r.flag_read) : Json(nullptr);
  j["traffic_differs"] = r.traffic_differs;
  j["exit"] = r.exit;
  j["program"] = r.program;
  if (r.first_failure) {
    const ScenarioFailure& f = *r.first_failure;
    j["first_failure"] = {{"where", f.where}, {"what", f.what}, {"tick", f.tick}, {"chip", f.chip},
                          {"expected", f.expected}, {"seen", f.seen}};
  } else {
    j["first_failure"] = nullptr;
  }
  j["reproducer"] = r.reproducer.empty() ? Json(nullptr) : Json(r.reproducer);
  j["command"] = r.command;
  return j;
}

RerunResult rerun_from(const Json& j) {
  RerunResult r;
  r.index = j.at("index").get<std::size_t>();
  r.fault = j.at("fault").get<std::string>();
  r.chain = j.at("chain").get<std::string>();
  r.chip = j.at("chip").get<std::size_t>();
  const Json& p = j.at("point");
  r.point = p.at("name").get<std::string>();
  r.tick = p.at("tick").get<Tick>();
  r.after_command = p.at("after_command").get<std::string>();
  const auto v = verdict_named(j.at("verdict").get<std::string>());
  if (!v) throw std::invalid_argument("unknown verdict " + j.at("verdict").get<std::string>());
  r.verdict = *v;
  if (!j.at("flag_read").is_null()) r.flag_read = j.at("flag_read").get<bool>();
  r.traffic_differs = j.at("traffic_differs").get<bool>();
  r.exit = j.at("exit").get<int>();
  r.program = j.at("program").get<std::string>();
  if (const Json& f = j.at("first_failure"); !f.is_null())
    r.first_failure = ScenarioFailure{f.at("where").get<std::string>(), f.at("what").get<std::string>(),
                                      f.at("tick").get<Tick>(), f.at("chip").get<std::string>(),
                                      f.at("expected").get<std::string>(), f.at("seen").get<std::string>()};
  if (!j.at("reproducer").is_null()) r.reproducer = j.at("reproducer").get<std::string>();
  r.command = j.at("command").get<std::string>();
  return r;
}

std::map<Verdict, std::size_t> tally(const CampaignReport& r) {
  std::map<Verdict, std::size_t> n;
  for (const RerunResult& x : r.reruns) ++n[x.verdict];
  return n;
}

std::string cell(const RerunResult& r) {
  switch (r.verdict) {
    case Verdict::detected: return "detected";
    case Verdict::survived: return r.flag_read.value_or(true) ? "survived" : "survived*";
    case Verdict::silent_failure: return "SILENT";
    case Verdict::hang: return "HANG";
    case Verdict::deadlock: return "DEADLOCK";
    case Verdict::crash: return "CRASH";
  }
  return "?";
}

}  // namespace

std::string_view to_string(Verdict v) {
  switch (v) {
    case Verdict::detected: return "detected";
    case Verdict::survived: return "survived";
    case Verdict::silent_failure: return "silent_failure";
    case Verdict::hang: return "hang";
    case Verdict::deadlock: return "deadlock";
    case Verdict::crash: return "crash";
  }
  return "?";
}

std::optional<Verdict> verdict_named(std::string_view name) {
  for (const Verdict v : kVerdicts)
    if (to_string(v) == name) return v;
  return std::nullopt;
}

Verdict classify_rerun(const std::optional<RunOutcome>& o, bool wall_killed) {
  if (wall_killed) return Verdict::hang;
  if (!o) return Verdict::crash;
  switch (o->status) {
    case kRunPassed: return Verdict::survived;
    case kRunExpectationFailed: return Verdict::silent_failure;
    case kRunTimedOut: return Verdict::hang;
    case kRunDeadlocked: return Verdict::deadlock;
    case kRunSanitizerError: return Verdict::detected;
    case kRunProgramFailed: return o->exited ? Verdict::detected : Verdict::crash;
    default: return Verdict::crash;
  }
}

std::optional<FailOn> parse_fail_on(std::string_view list, std::string& error) {
  FailOn on;
  on.verdicts.clear();
  std::vector<std::string> names;
  for (const Verdict v : kVerdicts) names.emplace_back(to_string(v));
  names.emplace_back("survived-unread");
  for (const std::string& word : comma_list(list)) {
    if (word == "survived-unread") {
      on.survived_unread = true;
    } else if (const auto v = verdict_named(word)) {
      on.verdicts.insert(*v);
    } else {
      const std::string near = closest_names(word, names);
      error = "--fail-on: '" + word + "' is not a verdict" + (near.empty() ? "" : " (did you mean " + near + "?)") +
              "; verdicts: detected, survived, survived-unread, silent_failure, hang, deadlock, crash";
      return std::nullopt;
    }
  }
  return on;
}

bool RerunResult::fails(const FailOn& on) const {
  if (on.verdicts.count(verdict)) return true;
  return on.survived_unread && verdict == Verdict::survived && flag_read && !*flag_read;
}

std::string campaign_json(const CampaignReport& r) {
  Json j;
  j["format"] = kFormat;
  j["program"] = r.program;
  j["board"] = r.board;
  j["scenario"] = r.scenario.empty() ? Json(nullptr) : Json(r.scenario);
  j["oracle"] = r.oracle;
  j["faults"] = r.faults;
  j["points"] = r.points;
  j["clean_run"] = {{"end_tick", r.clean_end_tick}, {"seconds", seconds(r.clean_end_tick)}};
  j["rerun_timeout_ticks"] = r.rerun_timeout_ticks;
  j["total"] = r.total;
  if (r.shard) j["shard"] = std::to_string(r.shard->first) + "/" + std::to_string(r.shard->second);
  j["complete"] = r.complete;
  Json summary = Json::object();
  const auto n = tally(r);
  for (const Verdict v : kVerdicts) summary[std::string(to_string(v))] = n.count(v) ? n.at(v) : 0;
  j["summary"] = summary;
  j["reruns"] = Json::array();
  for (const RerunResult& x : r.reruns) j["reruns"].push_back(rerun_json(x));
  return j.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

std::optional<CampaignReport> parse_campaign_json(std::string_view text, std::string& error) {
  try {
    const Json j = Json::parse(text);
    if (!j.is_object() || !j.contains("format") || j.at("format") != kFormat) {
      error = "not a campaign report (format " + std::string(kFormat) + ")";
      return std::nullopt;
    }
    CampaignReport r;
    r.program = j.at("program").get<std::vector<std::string>>();
    r.board = j.at("board").get<std::string>();
    if (!j.at("scenario").is_null()) r.scenario = j.at("scenario").get<std::string>();
    r.oracle = j.at("oracle").get<std::string>();
    r.faults = j.at("faults").get<std::vector<std::string>>();
    r.points = j.at("points").get<std::string>();
    r.clean_end_tick = j.at("clean_run").at("end_tick").get<Tick>();
    r.rerun_timeout_ticks = j.at("rerun_timeout_ticks").get<Tick>();
    r.total = j.at("total").get<std::size_t>();
    if (j.contains("shard")) {
      unsigned k = 0, n = 0;
      if (std::sscanf(j.at("shard").get<std::string>().c_str(), "%u/%u", &k, &n) != 2) throw std::invalid_argument("bad shard");
      r.shard = std::make_pair(k, n);
    }
    r.complete = j.at("complete").get<bool>();
    for (const Json& x : j.at("reruns")) r.reruns.push_back(rerun_from(x));
    return r;
  } catch (const std::exception& e) {
    error = std::string("not a campaign report: ") + e.what();
    return std::nullopt;
  }
}

std::optional<CampaignReport> merge_campaign_reports(const std::vector<CampaignReport>& parts, std::string& error) {
  if (parts.empty()) {
    error = "nothing to merge";
    return std::nullopt;
  }
  CampaignReport out = parts.front();
  out.shard.reset();
  out.reruns.clear();
  std::map<std::size_t, RerunResult> by_index;
  bool complete = true;
  for (const CampaignReport& p : parts) {
    if (p.program != out.program || p.board != out.board || p.scenario != out.scenario || p.faults != out.faults ||
        p.points != out.points || p.total != out.total || p.clean_end_tick != out.clean_end_tick) {
      error = "the reports are not shards of one campaign (program, board, scenario, faults, points or clean run differ)";
      return std::nullopt;
    }
    complete = complete && p.complete;
    for (const RerunResult& r : p.reruns)
      if (!by_index.emplace(r.index, r).second) {
        error = "rerun " + std::to_string(r.index) + " is in two of the reports (the same shard given twice?)";
        return std::nullopt;
      }
  }
  for (auto& [i, r] : by_index) out.reruns.push_back(std::move(r));
  out.complete = complete && out.reruns.size() == out.total;
  return out;
}

std::string campaign_summary(const CampaignReport& r) {
  std::ostringstream o;
  o << r.reruns.size() << (r.reruns.size() == 1 ? " rerun" : " reruns");
  const auto n = tally(r);
  bool first = true;
  for (const Verdict v : kVerdicts) {
    if (!n.count(v)) continue;
    o << (first ? ": " : ", ") << n.at(v) << " " << to_string(v);
    first = false;
  }
  if (!r.complete) o << " (incomplete: " << r.reruns.size() << " of " << r.total << " ran)";
  return o.str();
}

std::string campaign_matrix(const CampaignReport& r, const FailOn& on) {
  std::ostringstream o;
  // One table per chip: a row per fault, a column per point.
  std::vector<std::pair<std::string, std::size_t>> chips;
  for (const RerunResult& x : r.reruns)
    if (std::find(chips.begin(), chips.end(), std::make_pair(x.chain, x.chip)) == chips.end()) chips.emplace_back(x.chain, x.chip);
  for (const auto& [chain, chip] : chips) {
    std::vector<std::pair<std::string, Tick>> points;
    std::vector<std::string> faults;
    for (const RerunResult& x : r.reruns) {
      if (x.chain != chain || x.chip != chip) continue;
      if (std::find(points.begin(), points.end(), std::make_pair(x.point, x.tick)) == points.end()) points.emplace_back(x.point, x.tick);
      if (std::find(faults.begin(), faults.end(), x.fault) == faults.end()) faults.push_back(x.fault);
    }
    std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    o << chain << " chip " << chip << ":\n";
    std::size_t fw = 5;
    for (const auto& f : faults) fw = std::max(fw, f.size());
    o << "  " << std::string(fw, ' ');
    for (std::size_t i = 0; i < points.size(); ++i) o << "  " << std::string(10 - std::to_string(i + 1).size() - 1, ' ') << "#" << i + 1;
    o << "\n";
    for (const auto& f : faults) {
      o << "  " << f << std::string(fw - f.size(), ' ');
      for (const auto& p : points) {
        std::string c = "-";
        for (const RerunResult& x : r.reruns)
          if (x.chain == chain && x.chip == chip && x.fault == f && x.point == p.first) c = cell(x);
        o << "  " << std::string(c.size() < 10 ? 10 - c.size() : 0, ' ') << c;
      }
      o << "\n";
    }
    for (std::size_t i = 0; i < points.size(); ++i)
      o << "  #" << i + 1 << " " << points[i].first << " at " << seconds(points[i].second) << " s\n";
  }
  bool any_unread = false;
  for (const RerunResult& x : r.reruns) any_unread = any_unread || (x.verdict == Verdict::survived && x.flag_read == false);
  if (any_unread) o << "  survived*: survived without ever reading the fault's flag\n";
  for (const RerunResult& x : r.reruns)
    if (x.fails(on))
      o << "  " << to_string(x.verdict) << ": " << x.fault << " on " << x.chain << " chip " << x.chip << " at " << x.point << ": "
        << x.command << "\n";
  return o.str();
}

std::string campaign_junit(const CampaignReport& r, const FailOn& on) {
  // (fault, chain, chip) in the order of the reruns: the same for every run of the campaign.
  std::vector<std::tuple<std::string, std::string, std::size_t>> cases;
  for (const RerunResult& x : r.reruns) {
    const auto key = std::make_tuple(x.fault, x.chain, x.chip);
    if (std::find(cases.begin(), cases.end(), key) == cases.end()) cases.push_back(key);
  }
  std::size_t failures = 0;
  std::ostringstream body;
  for (const auto& [fault, chain, chip] : cases) {
    std::vector<const RerunResult*> bad;
    for (const RerunResult& x : r.reruns)
      if (x.fault == fault && x.chain == chain && x.chip == chip && x.fails(on)) bad.push_back(&x);
    body << "    <testcase classname=\"l6470emu.campaign\" name=\"" << xml(fault + " " + chain + " chip " + std::to_string(chip))
         << "\" time=\"0\"";
    if (bad.empty()) {
      body << "/>\n";
      continue;
    }
    ++failures;
    body << ">\n      <failure type=\"" << xml(std::string(to_string(bad.front()->verdict))) << "\" message=\""
         << xml(std::to_string(bad.size()) + " of the reruns failed: " + std::string(to_string(bad.front()->verdict)) + " at " +
                bad.front()->point)
         << "\">";
    for (const RerunResult* x : bad) {
      body << xml(std::string(to_string(x->verdict)) + " at " + x->point + " (" + seconds(x->tick) + " s): " + x->program);
      if (x->first_failure)
        body << xml("; " + x->first_failure->what + ": expected " + x->first_failure->expected + ", seen " + x->first_failure->seen);
      body << "\n" << xml("  reproduce: " + x->command) << "\n";
    }
    body << "</failure>\n    </testcase>\n";
  }
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x << "<testsuites name=\"l6470emu campaign\" tests=\"" << cases.size() << "\" failures=\"" << failures << "\" errors=\"0\">\n";
  x << "  <testsuite name=\"campaign\" tests=\"" << cases.size() << "\" failures=\"" << failures
    << "\" errors=\"0\" skipped=\"0\">\n";
  x << body.str();
  if (!r.complete) x << "    <system-out>incomplete: " << r.reruns.size() << " of " << r.total << " reruns ran</system-out>\n";
  x << "  </testsuite>\n</testsuites>\n";
  return x.str();
}

}  // namespace l6470emu
