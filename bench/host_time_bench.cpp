// The host-time benchmark: runs bench/host_time_workload.py (py-spidev + libgpiod, 60 s of
// host-time sleeps and polling around moves) under the preload library in wall time and in
// virtual time, and prints the wall time each took, whether their results agree, and how long
// each move lasted on the host's clock against its profile (computed from the model).
// Usage: l6470emu_host_time_bench [--virtual-only]
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "daisychain/chain.hpp"
#include "daisychain/host.hpp"

extern char** environ;

namespace {

using namespace l6470emu;

struct Run {
  double wall_s = 0;
  std::string out;
  int status = -1;
};

Run run_workload(const std::string& chain) {
  char out_path[] = "/tmp/l6470emu-host-time-XXXXXX";
  const int fd = mkstemp(out_path);
  std::vector<std::string> env_strings = {"LD_PRELOAD=" L6470EMU_PRELOAD, "L6470EMU_CHAIN=" + chain};
  for (char** e = environ; *e; ++e)
    if (std::strncmp(*e, "LD_PRELOAD=", 11) != 0 && std::strncmp(*e, "L6470EMU_", 9) != 0) env_strings.push_back(*e);
  std::vector<char*> envp;
  for (auto& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);
  std::string python = "/usr/bin/python3", script = L6470EMU_WORKLOAD;
  char* argv[] = {python.data(), script.data(), nullptr};
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, fd, 1);
  Run r;
  const auto t0 = std::chrono::steady_clock::now();
  pid_t pid = 0;
  if (posix_spawn(&pid, argv[0], &fa, nullptr, argv, envp.data()) == 0) {
    int status = 0;
    waitpid(pid, &status, 0);
    r.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  posix_spawn_file_actions_destroy(&fa);
  close(fd);
  std::ifstream in(out_path);
  r.out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  unlink(out_path);
  return r;
}

/// The profile's duration of a Move of `full_steps` at 1/128 from a power-up L6470, seconds.
double profile_s(bool forward, std::uint32_t full_steps) {
  Chain c(1);
  ChainHost h(c, 0);
  h.move(0, forward, full_steps * 128);
  const Tick start = c.now();
  while (!c.chip(0).busy_sync_pin()) c.advance_to(c.next_event_tick());
  return static_cast<double>(c.now() - start) / static_cast<double>(kTicksPerSecond);
}

std::string field(const std::string& line, const std::string& key) {
  const auto at = line.find(key + "=");
  if (at == std::string::npos) return "";
  const auto end = line.find(' ', at);
  return line.substr(at + key.size() + 1, end == std::string::npos ? std::string::npos : end - at - key.size() - 1);
}

std::vector<std::string> lines_starting(const std::string& text, const std::string& prefix) {
  std::vector<std::string> v;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);)
    if (l.rfind(prefix, 0) == 0) v.push_back(l);
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  const bool virtual_only = argc > 1 && std::strcmp(argv[1], "--virtual-only") == 0;
  std::printf("host-time benchmark: %s (60 s of host time: moves, sleeps, polling, BUSY events)\n", L6470EMU_WORKLOAD);
  const Run v1 = run_workload("bus=0 cs=0 chips=L6470; time=virtual");
  const Run v2 = run_workload("bus=0 cs=0 chips=L6470; time=virtual");
  Run w;
  if (!virtual_only) w = run_workload("bus=0 cs=0 chips=L6470");
  if (v1.status != 0 || v2.status != 0 || (!virtual_only && w.status != 0)) {
    std::fprintf(stderr, "workload failed (virtual %d/%d, wall %d):\n%s%s", v1.status, v2.status, w.status,
                 v1.out.c_str(), w.out.c_str());
    return 1;
  }
  const auto finals_v = lines_starting(v1.out, "final");
  std::printf("\n%-48s %12s %10s\n", "run", "wall time", "goal");
  std::printf("%-48s %11.3fs %10s\n", "time=virtual (60 s of host time)", v1.wall_s, "< 0.5 s");
  std::printf("%-48s %11.3fs %10s\n", "time=virtual, again", v2.wall_s, "-");
  if (!virtual_only) std::printf("%-48s %11.3fs %10s\n", "time=wall", w.wall_s, "-");
  std::printf("virtual runs identical: %s\n", v1.out == v2.out ? "yes (every line, durations included)" : "NO");
  if (v1.out != v2.out) {
    std::istringstream a(v1.out), b(v2.out);
    for (std::string la, lb; std::getline(a, la) && std::getline(b, lb);)
      if (la != lb) {
        std::printf("  first difference:\n    %s\n    %s\n", la.c_str(), lb.c_str());
        break;
      }
  }
  if (!virtual_only) {
    const auto finals_w = lines_starting(w.out, "final");
    // host_seconds and durations differ by scheduling in wall time; the motor's states must not.
    auto state = [](const std::string& l) { return l.substr(0, l.find(" host_seconds")); };
    bool same = !finals_w.empty() && !finals_v.empty() && state(finals_w[0]) == state(finals_v[0]);
    const auto mw = lines_starting(w.out, "move"), mv = lines_starting(v1.out, "move");
    same = same && mw.size() == mv.size();
    for (std::size_t i = 0; same && i < mw.size(); ++i) same = field(mw[i], "abs_pos") == field(mv[i], "abs_pos");
    std::printf("motor state wall vs virtual (after each move, after the run, at the end): %s\n",
                same ? "identical" : "DIFFERENT");
    if (!finals_w.empty()) std::printf("  wall:    %s\n", finals_w[0].c_str());
  }
  if (!finals_v.empty()) std::printf("  virtual: %s\n", finals_v[0].c_str());

  std::printf("\n%-34s %10s %12s %12s %10s %10s\n", "move (how the host waited)", "profile", "wall mode", "virtual",
              "wall err", "goal");
  const auto moves_v = lines_starting(v1.out, "move");
  const auto moves_w = virtual_only ? std::vector<std::string>{} : lines_starting(w.out, "move");
  for (std::size_t i = 0; i < moves_v.size(); ++i) {
    const std::string& l = moves_v[i];
    const double profile = profile_s(field(l, "dir") == "1", static_cast<std::uint32_t>(std::stoul(field(l, "full_steps"))));
    const double vs = std::stod(field(l, "seconds"));
    const std::string label = field(l, "full_steps") + " full steps, " + field(l, "wait");
    if (i < moves_w.size()) {
      const double ws = std::stod(field(moves_w[i], "seconds"));
      std::printf("%-34s %9.4fs %11.4fs %11.4fs %9.2f%% %10s\n", label.c_str(), profile, ws, vs,
                  100.0 * (ws - profile) / profile, "< 1 %");
    } else {
      std::printf("%-34s %9.4fs %12s %11.4fs %10s %10s\n", label.c_str(), profile, "-", vs, "-", "-");
    }
  }
  return 0;
}
