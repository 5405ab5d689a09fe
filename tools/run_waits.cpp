// A deadlock across the processes of a run, from the waits they publish (tools/run_waits.hpp).
#include "tools/run_waits.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <set>

#include "linux/process_waits.hpp"
#include "linux/unix_socket_diag.hpp"
#include "tools/proc_files.hpp"

namespace l6470emu {
namespace {

// The processes holding `target` ("pipe:[123]", "socket:[124]": their /proc/PID/fd links), as
// lsof finds them.
std::set<pid_t> holders(const std::map<pid_t, ProcessInfo>& all, const std::string& target) {
  std::set<pid_t> out;
  for (const auto& [pid, info] : all) {
    const std::string dir = "/proc/" + std::to_string(pid) + "/fd";
    for (const std::string& fd : numbered_entries(dir)) {
      char link[64];
      const ssize_t n = readlink((dir + "/" + fd).c_str(), link, sizeof link - 1);
      if (n > 0 && std::string(link, static_cast<std::size_t>(n)) == target) {
        out.insert(pid);
        break;
      }
    }
  }
  return out;
}

// Whether the pipe process `pid` waits on through descriptor `fd` is still pipe `inode`, empty,
// and written by someone (its waiter's read would block): opened again through /proc, a reader
// more for a moment, polled.
bool pipe_would_block(pid_t pid, int fd, unsigned long inode) {
  const std::string path = "/proc/" + std::to_string(pid) + "/fd/" + std::to_string(fd);
  const int again = open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (again < 0) return false;
  struct stat st {};
  pollfd p{again, POLLIN, 0};
  const bool same = fstat(again, &st) == 0 && st.st_ino == inode;
  const bool quiet = same && poll(&p, 1, 0) == 0;
  close(again);
  return quiet;
}

}  // namespace

std::unique_ptr<RunWaits> RunWaits::make(const std::string& report_path) {
  std::string dir = run_waits_directory(report_path);
  if (mkdir(dir.c_str(), 0700) != 0) return nullptr;
  return std::unique_ptr<RunWaits>(new RunWaits(std::move(dir)));
}

RunWaits::~RunWaits() {
  if (DIR* d = opendir(dir_.c_str())) {
    while (const dirent* e = readdir(d))
      if (std::strcmp(e->d_name, ".") != 0 && std::strcmp(e->d_name, "..") != 0) unlink((dir_ + "/" + e->d_name).c_str());
    closedir(d);
  }
  rmdir(dir_.c_str());
}

std::map<pid_t, ProcessWaits> RunWaits::published() const {
  std::map<pid_t, ProcessWaits> out;
  for (const std::string& pid : numbered_entries(dir_))
    if (const auto w = parse_process_waits(read_small_file(dir_ + "/" + pid)))
      out[static_cast<pid_t>(std::atol(pid.c_str()))] = *w;
  return out;
}

std::map<pid_t, std::vector<std::string>> RunWaits::said() const {
  std::map<pid_t, std::vector<std::string>> out;
  for (auto& [pid, w] : published()) out[pid] = std::move(w.threads);
  return out;
}

CrossProcessDeadlock RunWaits::look() const {
  // The published files first: without any, no /proc scan.
  const std::map<pid_t, ProcessWaits> published = this->published();
  if (published.empty()) return {};
  const std::map<pid_t, ProcessInfo> all = all_processes();
  const std::set<pid_t> run = live_descendants(all, getpid());
  if (run.empty()) return {};
  // Every process of the run waits on others...
  for (const pid_t p : run)
    if (!published.count(p)) return {};
  // ...and only on processes of the run.
  for (const pid_t p : run) {
    for (const WaitDependency& d : published.at(p).dependencies) {
      switch (d.kind) {
        case WaitDependency::Kind::other:
          return {};
        case WaitDependency::Kind::child:
          if (!run.count(d.pid)) return {};  // ended (a zombie to reap) or not the run's
          break;
        case WaitDependency::Kind::pipe: {
          if (!pipe_would_block(p, d.fd, d.inode)) return {};
          for (const pid_t holder : holders(all, "pipe:[" + std::to_string(d.inode) + "]"))
            if (!run.count(holder)) return {};  // another process (or this one, run) may write it
          break;
        }
        case WaitDependency::Kind::socket: {
          // Still connected to the same peer, nothing queued, and both ends held only by the run
          // (the peer held by someone: else its reader gets end of file).
          const UnixSocketInfo info = unix_socket_info(d.inode);
          if (!info.known || info.peer != d.peer || info.receive_queue != 0) return {};
          const std::set<pid_t> own = holders(all, "socket:[" + std::to_string(d.inode) + "]");
          const std::set<pid_t> peer = holders(all, "socket:[" + std::to_string(d.peer) + "]");
          if (!own.count(p) || peer.empty()) return {};
          for (const std::set<pid_t>* side : {&own, &peer})
            for (const pid_t holder : *side)
              if (!run.count(holder)) return {};
          break;
        }
      }
    }
  }
  CrossProcessDeadlock found;
  for (const pid_t p : run) {
    found.processes.push_back(p);
    const std::string who = "process " + std::to_string(p) + " (" + all.at(p).name + "): ";
    for (const std::string& t : published.at(p).threads) found.lines.push_back(who + t);
  }
  return found;
}

}  // namespace l6470emu
