// is_pid_name, numbered_entries, read_small_file, all_processes and live_descendants.
#include "tools/proc_files.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

namespace l6470emu {

bool is_pid_name(const char* s) {
  if (!*s) return false;
  for (; *s; ++s)
    if (*s < '0' || *s > '9') return false;
  return true;
}

std::string read_small_file(const std::string& path, std::size_t limit) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return {};
  std::string text;
  char buf[4096];
  for (ssize_t n; text.size() < limit && (n = read(fd, buf, sizeof buf)) > 0;) text.append(buf, static_cast<std::size_t>(n));
  close(fd);
  if (text.size() > limit) text.resize(limit);
  return text;
}

std::vector<std::string> numbered_entries(const std::string& dir) {
  std::vector<std::string> out;
  if (DIR* d = opendir(dir.c_str())) {
    while (const dirent* e = readdir(d))
      if (is_pid_name(e->d_name)) out.emplace_back(e->d_name);
    closedir(d);
  }
  return out;
}

std::map<pid_t, ProcessInfo> all_processes() {
  std::map<pid_t, ProcessInfo> out;
  for (const std::string& pid : numbered_entries("/proc")) {
    const std::string stat = read_small_file("/proc/" + pid + "/stat", 4096);
    const std::size_t open_paren = stat.find('('), close_paren = stat.rfind(')');
    if (open_paren == std::string::npos || close_paren == std::string::npos || close_paren < open_paren) continue;
    ProcessInfo p;
    p.name = stat.substr(open_paren + 1, close_paren - open_paren - 1);
    long parent = 0;
    if (std::sscanf(stat.c_str() + close_paren + 1, " %c %ld", &p.state, &parent) != 2) continue;
    p.parent = static_cast<pid_t>(parent);
    out[static_cast<pid_t>(std::atol(pid.c_str()))] = p;
  }
  return out;
}

std::set<pid_t> live_descendants(const std::map<pid_t, ProcessInfo>& all, pid_t root) {
  std::set<pid_t> out;
  for (const auto& [pid, info] : all) {
    if (info.state == 'Z' || info.state == 'X') continue;
    for (pid_t p = info.parent, hops = 0; p > 0 && hops < 4096; ++hops) {
      if (p == root) {
        out.insert(pid);
        break;
      }
      const auto it = all.find(p);
      if (it == all.end()) break;
      p = it->second.parent;
    }
  }
  return out;
}

}  // namespace l6470emu
