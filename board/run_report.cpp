// The run report's blocks: written by the fronts (preload, firmware), read by `l6470emu run`.
#include "board/run_report.hpp"

#include <algorithm>
#include <charconv>

namespace l6470emu {
namespace {

// One field on one line: tabs and line ends become spaces.
std::string field(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c == '\t' || c == '\n' || c == '\r') c = ' ';
  return out;
}

template <typename T>
bool number(std::string_view s, T& v) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

std::vector<std::string_view> split(std::string_view s, char sep) {
  std::vector<std::string_view> out;
  std::size_t at = 0;
  while (true) {
    const std::size_t n = s.find(sep, at);
    out.push_back(s.substr(at, n == std::string_view::npos ? std::string_view::npos : n - at));
    if (n == std::string_view::npos) return out;
    at = n + 1;
  }
}

}  // namespace

std::string_view to_string(RunEnd end) {
  constexpr std::string_view n[] = {"exit", "timeout", "deadlock", "sanitizer"};
  return n[static_cast<unsigned>(end)];
}

std::vector<std::string> detail_lines(std::string_view text) {
  std::vector<std::string> out;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t nl = std::min(text.find('\n', at), text.size());
    if (nl > at) out.emplace_back(text.substr(at, nl - at));
    at = nl + 1;
  }
  return out;
}

std::string format_run_report(const RunReport& r) {
  std::string out = "l6470emu-run-report 1\n";
  out += "pid " + std::to_string(r.pid) + "\n";
  out += "end " + std::string(to_string(r.end)) + "\n";
  out += "tick " + std::to_string(r.tick) + "\n";
  out += std::string("devices ") + (r.devices ? "1" : "0") + "\n";
  out += std::string("scenario ") + (r.scenario ? "1" : "0") + "\n";
  out += "judged " + std::to_string(r.outcome.judged) + "\n";
  for (const auto& d : r.detail) out += "detail " + field(d) + "\n";
  for (const auto& l : r.outcome.log) out += "log " + field(l) + "\n";
  for (const auto& p : r.outcome.passed) out += "pass " + field(p) + "\n";
  for (const ScenarioFailure& f : r.outcome.failures)
    out += "fail " + field(f.where) + "\t" + field(f.what) + "\t" + std::to_string(f.tick) + "\t" + field(f.chip) + "\t" +
           field(f.expected) + "\t" + field(f.seen) + "\n";
  for (const auto& p : r.outcome.pin_reads)
    out += "pinread " + field(p.chain) + "\t" + std::to_string(p.chip) + "\t" + field(p.pin) + "\t" + std::to_string(p.tick) + "\n";
  return out + ".\n";
}

std::vector<RunReport> parse_run_reports(std::string_view text) {
  std::vector<RunReport> out;
  RunReport cur;
  bool in_block = false, ok = true;
  for (std::string_view line : split(text, '\n')) {
    if (line == "l6470emu-run-report 1") {
      cur = RunReport{};
      in_block = true;
      ok = true;
      continue;
    }
    if (!in_block) continue;
    if (line == ".") {
      if (ok) out.push_back(std::move(cur));
      in_block = false;
      continue;
    }
    const std::size_t sp = line.find(' ');
    const std::string_view key = line.substr(0, sp);
    const std::string_view value = sp == std::string_view::npos ? std::string_view{} : line.substr(sp + 1);
    if (key == "pid") {
      ok = ok && number(value, cur.pid);
    } else if (key == "end") {
      bool known = false;
      for (RunEnd e : {RunEnd::exit, RunEnd::timeout, RunEnd::deadlock, RunEnd::sanitizer})
        if (value == to_string(e)) {
          cur.end = e;
          known = true;
        }
      ok = ok && known;
    } else if (key == "tick") {
      ok = ok && number(value, cur.tick);
    } else if (key == "devices") {
      cur.devices = value == "1";
    } else if (key == "scenario") {
      cur.scenario = value == "1";
    } else if (key == "judged") {
      ok = ok && number(value, cur.outcome.judged);
    } else if (key == "detail") {
      cur.detail.emplace_back(value);
    } else if (key == "log") {
      cur.outcome.log.emplace_back(value);
    } else if (key == "pass") {
      cur.outcome.passed.emplace_back(value);
    } else if (key == "fail") {
      const auto f = split(value, '\t');
      ScenarioFailure sf;
      if (f.size() != 6 || !number(f[2], sf.tick)) {
        ok = false;
        continue;
      }
      sf.where = f[0];
      sf.what = f[1];
      sf.chip = f[3];
      sf.expected = f[4];
      sf.seen = f[5];
      cur.outcome.failures.push_back(std::move(sf));
    } else if (key == "pinread") {
      const auto f = split(value, '\t');
      ScenarioOutcome::PinRead p;
      if (f.size() != 4 || !number(f[1], p.chip) || !number(f[3], p.tick)) {
        ok = false;
        continue;
      }
      p.chain = f[0];
      p.pin = f[2];
      cur.outcome.pin_reads.push_back(std::move(p));
    }
  }
  return out;
}

}  // namespace l6470emu
