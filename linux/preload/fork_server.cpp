// A campaign's snapshots in the program (linux/preload/fork_server.hpp). The fork happens inside
// the scheduler's move of the board to the injection tick, with its lock held: the process has
// one thread, so the child goes on from exactly there as a plain rerun would have (the fault's
// steps are due at that tick and fire at once). The child's descriptors that the parent shares
// are taken apart first: its standard output and error go to the rerun's file, each recording
// goes on into a copy of itself, and its wake-up descriptor is its own.
#include "linux/preload/fork_server.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "linux/clock.hpp"
#include "linux/fork_plan.hpp"
#include "linux/log.hpp"
#include "linux/preload/fd_holders.hpp"
#include "linux/preload/real.hpp"
#include "linux/preload/run.hpp"
#include "linux/preload/state.hpp"
#include "linux/preload/virtual_time.hpp"

namespace l6470emu::preload {
namespace {

struct Child {
  pid_t pid = 0;
  int pidfd = -1;  // readable once it ended (-1: poll every millisecond instead)
  std::string dir;
  std::int64_t started_ns = 0;
};

struct Server {
  DeviceBoard* board = nullptr;
  ForkPlan plan;
  std::size_t next = 0;  // the first job not yet reached
  std::vector<Child> children;
};

Server* g_server = nullptr;  // never freed: read at exit
std::atomic<bool> g_snapshot_forking{false};

void write_file(const std::string& path, const std::string& text) {
  const int fd = real::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return;
  raw_write_all(fd, text.data(), text.size());
  real::close(fd);
}

bool read_file(const std::string& path, std::string& out) {
  const int fd = real::open(path.c_str(), O_RDONLY | O_CLOEXEC, 0);
  if (fd < 0) return false;
  char buf[65536];
  for (ssize_t n; (n = real::read(fd, buf, sizeof buf)) != 0;) {
    if (n < 0) {
      if (errno == EINTR) continue;
      real::close(fd);
      return false;
    }
    out.append(buf, static_cast<std::size_t>(n));
  }
  real::close(fd);
  return true;
}

[[noreturn]] void refuse(const std::string& line) {
  const std::string text = "l6470emu: " + line + "\n";
  raw_write_all(2, text.data(), text.size());
  _exit(kRunUsage);
}

int count_threads() {
  DIR* d = real::opendir("/proc/self/task");
  if (!d) return -1;
  int n = 0;
  while (const dirent* e = real::readdir(d))
    if (e->d_name[0] != '.') ++n;
  real::closedir(d);
  return n;
}

// Why the process cannot be forked as a rerun now (empty: it can).
std::string cannot_fork() {
  if (!run_devices_used()) return "the process had not used the chips yet";
  const int threads = count_threads();
  if (threads != 1) return "the program had " + std::to_string(threads) + " threads at the tick (a snapshot needs one)";
  if (virtual_timerfds_exist()) return "the program held timerfds on the virtual clocks (parent and child would share them)";
  // Descriptors whose events the board writes (gpio edge events, line-info changes) would be
  // shared by parent and child; spidev and value-only line handles carry none.
  DIR* d = real::opendir("/proc/self/fd");
  std::string why;
  if (!d) return "/proc/self/fd cannot be read";
  while (const dirent* e = real::readdir(d)) {
    if (e->d_name[0] == '.') continue;
    const FdEntry* entry = fd_entry(std::atoi(e->d_name));
    if (entry && entry->kind != HandleKind::spidev && entry->kind != HandleKind::line_handle_v1) {
      why = "the program held a gpiochip or a gpio line request with events (descriptor " + std::string(e->d_name) +
            "; parent and child would share its events)";
      break;
    }
  }
  real::closedir(d);
  return why;
}

// Reaps the children that ended (and ends those past the wall-clock limit, whole) until at most
// `keep` run; each one's directory gets its "ended" file.
void reap(std::size_t keep) {
  Server& s = *g_server;
  while (true) {
    for (std::size_t i = 0; i < s.children.size();) {
      Child& c = s.children[i];
      int ws = 0;
      pid_t r = static_cast<pid_t>(syscall(SYS_wait4, c.pid, &ws, WNOHANG, nullptr));
      if (r == 0 && s.plan.wall_ns > 0 && monotonic_ns() - c.started_ns > s.plan.wall_ns) {
        kill(-c.pid, SIGKILL);
        kill(c.pid, SIGKILL);
        do r = static_cast<pid_t>(syscall(SYS_wait4, c.pid, &ws, 0, nullptr));
        while (r < 0 && errno == EINTR);
        write_file(c.dir + "/" + fork_files::wall_killed, "\n");
      }
      if (r == 0 || (r < 0 && errno == EINTR)) {
        ++i;
        continue;
      }
      if (r == c.pid) {
        kill(-c.pid, SIGKILL);  // whatever the rerun left behind in its group
        write_file(c.dir + "/" + fork_files::ended, std::to_string(c.pid) + " " + std::to_string(ws) + "\n");
      }
      if (c.pidfd >= 0) real::close(c.pidfd);
      s.children.erase(s.children.begin() + static_cast<std::ptrdiff_t>(i));
    }
    if (s.children.size() <= keep) return;
    // Until one ends (its pidfd becomes readable) or the first wall-clock limit comes.
    std::vector<pollfd> ended;
    std::int64_t wait_ns = 100'000'000;
    for (const Child& c : s.children) {
      if (c.pidfd < 0) wait_ns = std::min<std::int64_t>(wait_ns, 1'000'000);
      else ended.push_back(pollfd{c.pidfd, POLLIN, 0});
      if (s.plan.wall_ns > 0)
        wait_ns = std::min(wait_ns, std::max<std::int64_t>(0, c.started_ns + s.plan.wall_ns - monotonic_ns()) + 1'000'000);
    }
    const timespec ts{static_cast<time_t>(wait_ns / 1'000'000'000), static_cast<long>(wait_ns % 1'000'000'000)};
    syscall(SYS_ppoll, ended.data(), ended.size(), &ts, nullptr, 0);
  }
}

void at_exit() {
  if (!g_server) return;
  for (std::size_t j = g_server->next; j < g_server->plan.jobs.size(); ++j)
    write_file(g_server->plan.jobs[j].dir + "/" + fork_files::not_forked, "the program ended before the tick\n");
  g_server->next = g_server->plan.jobs.size();
  reap(0);
}

// Maps `copy` over every shared mapping of the file `from` (a recording written through its
// pages: linux/recording_output.hpp), at the same addresses and offsets: the child's stores go
// to its copy, not to the parent's file.
bool remap_onto(const std::string& from, int copy) {
  std::string maps;
  if (!read_file("/proc/self/maps", maps)) return false;
  for (std::size_t at = 0; at < maps.size();) {
    const std::size_t nl = std::min(maps.find('\n', at), maps.size());
    const std::string line = maps.substr(at, nl - at);
    at = nl + 1;
    const std::size_t slash = line.find('/');
    if (slash == std::string::npos || line.substr(slash) != from) continue;
    unsigned long start = 0, end = 0, offset = 0;
    char perms[5] = {};
    if (std::sscanf(line.c_str(), "%lx-%lx %4s %lx", &start, &end, perms, &offset) != 4 || perms[3] != 's') continue;
    const int prot = (perms[0] == 'r' ? PROT_READ : 0) | (perms[1] == 'w' ? PROT_WRITE : 0);
    if (mmap(reinterpret_cast<void*>(start), end - start, prot, MAP_SHARED | MAP_FIXED, copy, static_cast<off_t>(offset)) ==
        MAP_FAILED)
      return false;
  }
  return true;
}

// Replaces descriptor `fd` (open on `from`) by one open on a copy of `from` at `to`, at the same
// offset and under the same mappings: what the parent wrote so far, and the child's lines from
// now on.
bool continue_recording(int fd, const std::string& from, const std::string& to) {
  std::string text;
  if (!read_file(from, text)) return false;
  const int flags = fcntl(fd, F_GETFL);
  const int fd_flags = fcntl(fd, F_GETFD);
  const off_t at = lseek(fd, 0, SEEK_CUR);
  const int copy = real::open(to.c_str(), O_RDWR | O_CREAT | O_TRUNC | (flags & O_APPEND), 0644);
  if (copy < 0) return false;
  const bool ok = raw_write_all(copy, text.data(), text.size()) && remap_onto(from, copy) &&
                  (at < 0 || lseek(copy, at, SEEK_SET) == at) &&
                  real::dup3(copy, fd, (fd_flags & FD_CLOEXEC) ? O_CLOEXEC : 0) == fd;
  real::close(copy);
  return ok;
}

// In the child: the rerun of `job` from here on. Once its recordings are its own it writes a
// byte to `ready`: until then the parent must not write to its own.
void become_rerun(const ForkPlan::Job& job, const ForkPlan& plan, DeviceBoard& board, int ready) {
  setpgid(0, 0);
  prctl(PR_SET_PDEATHSIG, SIGKILL);  // the campaign stopped the clean run: its reruns end with it
  const std::string& dir = job.dir;
  const int out = real::open((dir + "/" + fork_files::output).c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int in = real::open("/dev/null", O_RDONLY | O_CLOEXEC, 0);
  if (out >= 0) {
    real::dup3(out, 1, 0);
    real::dup3(out, 2, 0);
    real::close(out);
  }
  if (in >= 0) {
    real::dup3(in, 0, 0);
    real::close(in);
  }
  // Each recording the parent has open goes on into the rerun's copy.
  for (const std::string& from : plan.recordings) {
    const std::string to = dir + from.substr(from.rfind('/'));
    DIR* d = real::opendir("/proc/self/fd");
    if (!d) continue;
    while (const dirent* e = real::readdir(d)) {
      if (e->d_name[0] == '.') continue;
      if (link_of(std::string("/proc/self/fd/") + e->d_name) != from) continue;
      if (!continue_recording(std::atoi(e->d_name), from, to)) refuse("a rerun's recording " + to + " cannot be written");
    }
    real::closedir(d);
  }
  const char byte = 1;
  raw_write_all(ready, &byte, 1);
  real::close(ready);
  run_continue_as_rerun(dir + "/" + fork_files::report);
  std::string text, error;
  if (!read_file(dir + "/" + fork_files::steps, text)) refuse("the rerun's steps " + dir + "/" + fork_files::steps + " cannot be read");
  const auto steps = deserialize_scenario(text, error);
  if (!steps) refuse(dir + "/" + fork_files::steps + ": " + error);
  try {
    board.add_scenario_steps(steps->steps);
  } catch (const std::exception& e) {
    refuse(std::string("the rerun's steps: ") + e.what());
  }
}

}  // namespace

void start_fork_server(DeviceBoard& board) {
  const char* path = std::getenv(kForkPlanEnv);
  if (!path || !*path) return;
  const std::string where = path;
  unsetenv(kForkPlanEnv);
  std::string text, error;
  if (!read_file(where, text)) refuse(std::string(kForkPlanEnv) + "=" + where + " cannot be read");
  auto plan = parse_fork_plan(text, error);
  if (!plan) refuse(where + ": " + error);
  g_server = new Server{&board, std::move(*plan), 0, {}};
  std::atexit(at_exit);
}

Tick fork_server_next_tick() { return g_server && g_server->next < g_server->plan.jobs.size() ? g_server->plan.jobs[g_server->next].tick : kNever; }

void fork_server_reached(Tick now) {
  while (g_server && g_server->next < g_server->plan.jobs.size() && g_server->plan.jobs[g_server->next].tick <= now) {
    Server& s = *g_server;
    const ForkPlan::Job job = s.plan.jobs[s.next++];
    std::string why = job.tick < now ? "virtual time went past the tick without stopping there" : cannot_fork();
    if (!why.empty()) {
      write_file(job.dir + "/" + fork_files::not_forked, why + "\n");
      continue;
    }
    reap(s.plan.children - 1);
    for (FILE* f : {stdout, stderr})  // (what the parent printed is not the child's to print again)
      if (ftrylockfile(f) == 0) {
        fflush_unlocked(f);
        funlockfile(f);
      }
    int ready[2];
    if (pipe2(ready, O_CLOEXEC) != 0) {
      write_file(job.dir + "/" + fork_files::not_forked, std::string("pipe failed: ") + std::strerror(errno) + "\n");
      continue;
    }
    g_snapshot_forking.store(true);
    const pid_t pid = fork();
    g_snapshot_forking.store(false);
    if (pid == 0) {
      const ForkPlan plan = s.plan;
      DeviceBoard& board = *s.board;
      for (const Child& c : s.children)  // (its siblings are not its to wait for)
        if (c.pidfd >= 0) real::close(c.pidfd);
      g_server = nullptr;  // (the parent's; never freed)
      real::close(ready[0]);
      if (VirtualHostTime* vt = installed_virtual_time()) vt->after_snapshot_fork_child();
      become_rerun(job, plan, board, ready[1]);
      return;
    }
    real::close(ready[1]);
    char byte = 0;
    while (pid > 0 && real::read(ready[0], &byte, 1) < 0 && errno == EINTR) {
    }
    real::close(ready[0]);
    if (pid < 0) {
      write_file(job.dir + "/" + fork_files::not_forked, std::string("fork failed: ") + std::strerror(errno) + "\n");
      continue;
    }
    s.children.push_back(Child{pid, static_cast<int>(syscall(SYS_pidfd_open, pid, 0)), job.dir, monotonic_ns()});
  }
}

void fork_server_after_fork_child() {
  if (!g_snapshot_forking.load()) g_server = nullptr;
}

void fork_server_leave() { g_server = nullptr; }

bool snapshot_forking() { return g_snapshot_forking.load(); }

}  // namespace l6470emu::preload
