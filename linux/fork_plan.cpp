// The snapshot plan's text (linux/fork_plan.hpp).
#include "linux/fork_plan.hpp"

#include <algorithm>
#include <charconv>

namespace l6470emu {
namespace {

constexpr std::string_view kFirstLine = "l6470emu fork plan 1";

template <typename T>
bool number(std::string_view s, T& out) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && !s.empty();
}

}  // namespace

std::string format_fork_plan(const ForkPlan& plan) {
  std::string out = std::string(kFirstLine) + "\n";
  out += "children " + std::to_string(plan.children) + "\n";
  out += "wall_ns " + std::to_string(plan.wall_ns) + "\n";
  for (const std::string& r : plan.recordings) out += "record " + r + "\n";
  for (const ForkPlan::Job& j : plan.jobs) out += "job " + std::to_string(j.tick) + " " + j.dir + "\n";
  return out;
}

std::optional<ForkPlan> parse_fork_plan(std::string_view text, std::string& error) {
  ForkPlan plan;
  std::size_t at = 0, line_no = 0;
  auto fail = [&](const std::string& why) {
    error = "line " + std::to_string(line_no) + ": " + why;
    return std::nullopt;
  };
  while (at < text.size()) {
    const std::size_t nl = text.find('\n', at);
    if (nl == std::string_view::npos) return fail("the plan does not end with a newline");
    const std::string_view line = text.substr(at, nl - at);
    at = nl + 1;
    ++line_no;
    if (line_no == 1) {
      if (line != kFirstLine) return fail("not a fork plan");
      continue;
    }
    const std::size_t space = line.find(' ');
    const std::string_view key = line.substr(0, space), rest = space == std::string_view::npos ? "" : line.substr(space + 1);
    if (key == "children") {
      if (!number(rest, plan.children) || plan.children == 0) return fail("children takes a number above 0");
    } else if (key == "wall_ns") {
      if (!number(rest, plan.wall_ns) || plan.wall_ns < 0) return fail("wall_ns takes a number of nanoseconds");
    } else if (key == "record") {
      if (rest.empty() || rest.front() != '/') return fail("record takes an absolute path");
      plan.recordings.emplace_back(rest);
    } else if (key == "job") {
      const std::size_t sp = rest.find(' ');
      ForkPlan::Job j;
      if (sp == std::string_view::npos || !number(rest.substr(0, sp), j.tick)) return fail("job takes a tick and a directory");
      j.dir = std::string(rest.substr(sp + 1));
      if (j.dir.empty() || j.dir.front() != '/') return fail("a job's directory is an absolute path");
      if (!plan.jobs.empty() && j.tick < plan.jobs.back().tick) return fail("the jobs are not in order of tick");
      plan.jobs.push_back(std::move(j));
    } else {
      return fail("unknown key " + std::string(key));
    }
  }
  if (line_no == 0) return fail("empty");
  return plan;
}

}  // namespace l6470emu
