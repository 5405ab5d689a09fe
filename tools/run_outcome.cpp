// run --outcome's file: nlohmann-json both ways.
#include "tools/run_outcome.hpp"

#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

namespace l6470emu {

bool write_run_outcome(const std::string& path, const RunOutcome& o) {
  nlohmann::json j;
  j["status"] = o.status;
  j["exited"] = o.exited;
  j["code"] = o.code;
  j["signal"] = o.signal;
  j["end_tick"] = o.end_tick;
  j["ended"] = o.ended;
  j["detail"] = o.detail;
  j["failures"] = nlohmann::json::array();
  for (const ScenarioFailure& f : o.failures)
    j["failures"].push_back({{"where", f.where}, {"what", f.what}, {"tick", f.tick}, {"chip", f.chip},
                             {"expected", f.expected}, {"seen", f.seen}});
  j["pin_reads"] = nlohmann::json::array();
  for (const auto& p : o.pin_reads)
    j["pin_reads"].push_back({{"chain", p.chain}, {"chip", p.chip}, {"pin", p.pin}, {"tick", p.tick}});
  std::ofstream out(path, std::ios::trunc);
  out << j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  out.close();
  return static_cast<bool>(out);
}

std::optional<RunOutcome> read_run_outcome(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    const nlohmann::json j = nlohmann::json::parse(std::string(std::istreambuf_iterator<char>(in), {}));
    RunOutcome o;
    o.status = j.at("status").get<int>();
    o.exited = j.at("exited").get<bool>();
    o.code = j.at("code").get<int>();
    o.signal = j.at("signal").get<int>();
    o.end_tick = j.at("end_tick").get<Tick>();
    o.ended = j.at("ended").get<std::string>();
    o.detail = j.at("detail").get<std::vector<std::string>>();
    for (const auto& f : j.at("failures"))
      o.failures.push_back(ScenarioFailure{f.at("where").get<std::string>(), f.at("what").get<std::string>(),
                                           f.at("tick").get<Tick>(), f.at("chip").get<std::string>(),
                                           f.at("expected").get<std::string>(), f.at("seen").get<std::string>()});
    for (const auto& p : j.at("pin_reads"))
      o.pin_reads.push_back(ScenarioOutcome::PinRead{p.at("chain").get<std::string>(), p.at("chip").get<std::size_t>(),
                                                     p.at("pin").get<std::string>(), p.at("tick").get<Tick>()});
    return o;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

}  // namespace l6470emu
