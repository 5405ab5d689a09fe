// Left processes: PR_SET_CHILD_SUBREAPER, our children found by the parent pid in /proc/PID/stat,
// each one waited for by its pid (never waitpid(-1), which could take the status of a child
// that is someone else's business in this process).
#include "tools/left_processes.hpp"

#include <dirent.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

namespace l6470emu {
namespace {

std::mutex g_mutex;
std::set<pid_t> g_children_before;  // children this process had before the program

/// The parent pid and the name of process `pid` ("" name when it is gone).
bool read_stat(pid_t pid, pid_t& parent, std::string& name) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  if (!std::getline(in, text)) return false;
  // "PID (NAME) STATE PPID ...": NAME may hold spaces and parentheses; it ends at the last ')'.
  const std::size_t open = text.find('('), close = text.rfind(')');
  if (open == std::string::npos || close == std::string::npos || close < open) return false;
  name = text.substr(open + 1, close - open - 1);
  std::istringstream rest(text.substr(close + 1));
  char state = 0;
  long ppid = 0;
  if (!(rest >> state >> ppid)) return false;
  parent = static_cast<pid_t>(ppid);
  return true;
}

/// The children this process did not have before the program, waited for when they have ended:
/// those still running, with their names.
std::vector<std::pair<pid_t, std::string>> left_running() {
  std::vector<std::pair<pid_t, std::string>> running;
  std::set<pid_t> before;
  {
    std::lock_guard lock(g_mutex);
    before = g_children_before;
  }
  for (const pid_t pid : child_processes()) {
    if (before.count(pid)) continue;
    int status = 0;
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid || (r < 0 && errno == ECHILD)) continue;  // ended (now reaped), or not ours after all
    pid_t parent = 0;
    std::string name;
    read_stat(pid, parent, name);
    running.emplace_back(pid, name);
  }
  return running;
}

}  // namespace

std::vector<pid_t> child_processes() {
  std::vector<pid_t> children;
  const pid_t self = getpid();
  DIR* proc = opendir("/proc");
  if (!proc) return children;
  while (const dirent* d = readdir(proc)) {
    if (!std::isdigit(static_cast<unsigned char>(d->d_name[0]))) continue;
    const pid_t pid = static_cast<pid_t>(std::atol(d->d_name));
    pid_t parent = 0;
    std::string name;
    if (read_stat(pid, parent, name) && parent == self) children.push_back(pid);
  }
  closedir(proc);
  return children;
}

bool adopt_orphans_from_now() {
  const std::vector<pid_t> now = child_processes();
  {
    std::lock_guard lock(g_mutex);
    g_children_before.insert(now.begin(), now.end());
  }
  return prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) == 0;
}

LeftProcesses end_left_processes(std::chrono::milliseconds grace, std::chrono::milliseconds term_grace) {
  using Clock = std::chrono::steady_clock;
  constexpr auto kPoll = std::chrono::milliseconds(10);
  LeftProcesses left;
  // Those that end by themselves within the grace period are only waited for.
  const auto grace_end = Clock::now() + grace;
  std::vector<std::pair<pid_t, std::string>> running = left_running();
  while (!running.empty() && Clock::now() < grace_end) {
    std::this_thread::sleep_for(kPoll);
    running = left_running();
  }
  if (running.empty()) return left;
  for (const auto& [pid, name] : running) left.running.push_back(std::to_string(pid) + " " + name);
  // The rest: SIGTERM, then SIGKILL. Each one ended hands its own children to this process,
  // which ends them in turn; a process that forks faster than that is given up on.
  const auto kill_at = Clock::now() + term_grace;
  const auto give_up_at = kill_at + std::chrono::seconds(3);
  std::set<pid_t> termed;
  while (!running.empty()) {
    const auto now = Clock::now();
    if (now >= give_up_at) {
      left.unended = running.size();
      break;
    }
    for (const auto& [pid, name] : running) {
      if (now >= kill_at) {
        kill(pid, SIGKILL);
        left.killed = true;
      } else if (termed.insert(pid).second) {
        kill(pid, SIGTERM);
      }
    }
    std::this_thread::sleep_for(kPoll);
    running = left_running();
  }
  return left;
}

std::string LeftProcesses::line(std::chrono::milliseconds grace) const {
  if (running.empty()) return "";
  const std::size_t n = running.size();
  std::string names;
  for (std::size_t i = 0; i < std::min<std::size_t>(n, 5); ++i) names += (i ? ", " : "") + running[i];
  if (n > 5) names += ", ...";
  std::ostringstream s;
  s << "the program left " << n << (n == 1 ? " process" : " processes") << " running (" << names << ") "
    << static_cast<double>(grace.count()) / 1000 << " s after it ended: ended "
    << (n == 1 ? "it" : "them") << " with " << (killed ? "SIGTERM, then SIGKILL" : "SIGTERM");
  if (unended) s << "; " << unended << " could not be ended (they keep starting others)";
  return s.str();
}

}  // namespace l6470emu
