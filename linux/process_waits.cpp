// A process's published waits, as text (linux/process_waits.hpp).
#include "linux/process_waits.hpp"

#include <charconv>

namespace l6470emu {
namespace {

// The unsigned number at the start of `s` (advanced past it and one blank); false when none.
template <typename N>
bool take_number(std::string_view& s, N& out) {
  const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), out);
  if (error != std::errc() || end == s.data()) return false;
  s.remove_prefix(static_cast<std::size_t>(end - s.data()));
  if (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  return true;
}

}  // namespace

std::string run_waits_directory(const std::string& report_path) { return report_path + ".waits"; }

std::string format_process_waits(const ProcessWaits& waits) {
  std::string out;
  for (const WaitDependency& d : waits.dependencies) {
    switch (d.kind) {
      case WaitDependency::Kind::child: out += "child " + std::to_string(d.pid) + "\n"; break;
      case WaitDependency::Kind::pipe: out += "pipe " + std::to_string(d.inode) + " " + std::to_string(d.fd) + "\n"; break;
      case WaitDependency::Kind::socket:
        out += "socket " + std::to_string(d.inode) + " " + std::to_string(d.peer) + " " + std::to_string(d.fd) + "\n";
        break;
      case WaitDependency::Kind::other: out += "other\n"; break;
    }
  }
  for (const std::string& t : waits.threads) {
    std::string line = t;
    for (char& c : line)
      if (c == '\n') c = ' ';
    out += "| " + line + "\n";
  }
  return out;
}

std::optional<ProcessWaits> parse_process_waits(std::string_view text) {
  ProcessWaits w;
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    if (nl == std::string_view::npos) return std::nullopt;  // a file cut short
    std::string_view line = text.substr(0, nl);
    text.remove_prefix(nl + 1);
    if (line.starts_with("| ")) {
      w.threads.emplace_back(line.substr(2));
      continue;
    }
    WaitDependency d;
    if (line == "other") {
      w.dependencies.push_back(d);
    } else if (line.starts_with("child ")) {
      line.remove_prefix(6);
      d.kind = WaitDependency::Kind::child;
      if (!take_number(line, d.pid) || !line.empty() || d.pid <= 0) return std::nullopt;
      w.dependencies.push_back(d);
    } else if (line.starts_with("pipe ")) {
      line.remove_prefix(5);
      d.kind = WaitDependency::Kind::pipe;
      if (!take_number(line, d.inode) || !take_number(line, d.fd) || !line.empty() || d.fd < 0) return std::nullopt;
      w.dependencies.push_back(d);
    } else if (line.starts_with("socket ")) {
      line.remove_prefix(7);
      d.kind = WaitDependency::Kind::socket;
      if (!take_number(line, d.inode) || !take_number(line, d.peer) || !take_number(line, d.fd) || !line.empty() ||
          d.fd < 0)
        return std::nullopt;
      w.dependencies.push_back(d);
    } else {
      return std::nullopt;
    }
  }
  return w;
}

}  // namespace l6470emu
