// What a run's threads are blocked in, from /proc (tools/run_blocked.hpp).
#include "tools/run_blocked.hpp"
#include "tools/proc_files.hpp"

#include <unistd.h>

#include <cstdlib>
#include <map>
#include <set>

namespace l6470emu {
namespace {

std::string read_text(const std::string& path) {
  std::string s = read_small_file(path, 511);
  while (!s.empty() && (s.back() == '\n' || s.back() == '\0')) s.pop_back();
  return s;
}

// System calls whose first argument is a descriptor.
bool takes_fd(long n) {
  switch (n) {
    case 0: case 19: case 45: case 47: case 232: case 281: case 441: return true;  // read readv recvfrom recvmsg epoll_wait/pwait/pwait2
    default: return false;
  }
}

/// The name of x86-64 system call `number` among those a program blocks in ("read", "wait4"),
/// or "system call N" (another architecture's numbers are not named).
std::string blocking_syscall_name(long number) {
#if defined(__x86_64__)
  static const std::map<long, const char*> names = {
      {0, "read"},        {1, "write"},          {7, "poll"},          {19, "readv"},         {23, "select"},
      {34, "pause"},      {35, "nanosleep"},     {43, "accept"},       {42, "connect"},       {45, "recvfrom"},
      {47, "recvmsg"},    {61, "wait4"},         {128, "rt_sigtimedwait"}, {130, "rt_sigsuspend"}, {202, "futex"},
      {230, "clock_nanosleep"}, {232, "epoll_wait"}, {247, "waitid"},  {257, "openat"},       {270, "pselect6"},
      {271, "ppoll"},     {281, "epoll_pwait"},  {288, "accept4"},     {441, "epoll_pwait2"}, {2, "open"},
  };
  if (const auto it = names.find(number); it != names.end()) return it->second;
#endif
  return "system call " + std::to_string(number);
}

}  // namespace

std::vector<std::string> blocked_threads(const std::map<pid_t, std::vector<std::string>>& said) {
  const std::map<pid_t, ProcessInfo> all = all_processes();
  const std::set<pid_t> run = live_descendants(all, getpid());
  std::vector<std::string> lines;
  for (const pid_t pid : run) {
    const std::string proc = "/proc/" + std::to_string(pid);
    const std::string who = "process " + std::to_string(pid) + " (" + all.at(pid).name + ")";
    if (const auto it = said.find(pid); it != said.end() && !it->second.empty()) {
      for (const std::string& t : it->second) lines.push_back(who + ": " + t);
      continue;
    }
    for (const std::string& tid : numbered_entries(proc + "/task")) {
      const std::string task = proc + "/task/" + tid;
      const std::string syscall = read_text(task + "/syscall"), wchan = read_text(task + "/wchan");
      std::string what;
      if (syscall.empty()) {
        what = "unknown (its /proc entry cannot be read)";
      } else if (syscall == "running") {
        what = "running";
      } else {
        char* end = nullptr;
        const long n = std::strtol(syscall.c_str(), &end, 10);
        if (n < 0) {
          what = "not in a system call (computing)";
        } else {
          what = blocking_syscall_name(n) + "()";
          if (takes_fd(n)) {
            const long fd = std::strtol(end, nullptr, 16);  // the arguments are in hex
            char link[128] = {};
            const std::string fd_path = proc + "/fd/" + std::to_string(fd);
            const ssize_t k = readlink(fd_path.c_str(), link, sizeof link - 1);
            what += " of fd " + std::to_string(fd) + (k > 0 ? " (" + std::string(link, static_cast<std::size_t>(k)) + ")" : "");
          }
        }
        if (!wchan.empty() && wchan != "0") what += " (kernel: " + wchan + ")";
      }
      lines.push_back(who + " thread " + tid + ": " + what);
    }
  }
  return lines;
}

}  // namespace l6470emu
