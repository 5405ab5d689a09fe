// wait, waitpid, wait3, wait4 and waitid in virtual time: a call that would block first waits, as a
// covered wait, until a child it waits for has something to report (woken through the children's
// pidfds, and a look every 10 ms of real time for the rest: a child forked meanwhile, a stop), then
// the C library's call returns it. The waiting thread counts as waiting, so virtual time moves for
// the process's other threads; a child is another process, so such a wait is never part of this
// process's own deadlock: a child deadlocked itself reports its deadlock and ends, and processes
// waiting on each other are `run`'s to see (docs/linux.md, Deadlocks).
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "linux/preload/descriptor_wait.hpp"
#include "linux/preload/real.hpp"

using namespace l6470emu;
using namespace l6470emu::preload;

namespace {

// A child that reports where no pidfd wakes the wait (forked after it began, stopped, continued)
// is seen this often.
constexpr std::int64_t kChildRecheckNs = 10'000'000;
// At most this many pidfds per wait (the rest are seen by the periodic look).
constexpr std::size_t kMaxPidfds = 64;

// Closes the pidfds when the wait is over.
struct Pidfds {
  std::vector<pollfd> fds;
  bool missing = false;  // a child has no pidfd here
  ~Pidfds() {
    for (const pollfd& p : fds) real::close(p.fd);
  }
  void add(pid_t pid) {
    const int fd = fds.size() >= kMaxPidfds ? -1 : static_cast<int>(syscall(SYS_pidfd_open, pid, 0));
    if (fd >= 0)
      fds.push_back({fd, POLLIN, 0});
    else
      missing = true;
  }
};

// The process's children now (/proc/self/task/TID/children of every thread).
std::vector<pid_t> children() {
  std::vector<pid_t> out;
  DIR* d = real::opendir("/proc/self/task");
  if (!d) return out;
  while (const dirent* e = real::readdir(d)) {
    if (e->d_name[0] == '.') continue;
    const std::string path = std::string("/proc/self/task/") + e->d_name + "/children";
    const int fd = real::open(path.c_str(), O_RDONLY | O_CLOEXEC, 0);
    if (fd < 0) continue;
    std::string text;
    char buf[512];
    for (ssize_t n; (n = real::read(fd, buf, sizeof buf)) > 0 && text.size() < 65536;)
      text.append(buf, static_cast<std::size_t>(n));
    real::close(fd);
    for (const char* p = text.c_str(); *p;) {
      char* end = nullptr;
      const long pid = std::strtol(p, &end, 10);
      if (end == p) break;
      if (pid > 0) out.push_back(static_cast<pid_t>(pid));
      p = end;
    }
  }
  real::closedir(d);
  return out;
}

// Whether a child `idtype`/`id` selects has something to report for `events` (WEXITED,
// WSTOPPED, WCONTINUED), or the call would fail at once (no such child): the real call then
// returns without blocking.
bool child_ready(idtype_t idtype, id_t id, int events) {
  siginfo_t info{};
  const int saved = errno;
  const int r = real::waitid(idtype, id, &info, events | WNOHANG | WNOWAIT);
  errno = saved;
  return r != 0 || info.si_pid != 0;
}

// The covered wait before a blocking wait call. `options` as the caller gave them, in waitid's
// terms (WEXITED etc.).
ReadWait wait_for_child(VirtualHostTime& vt, idtype_t idtype, id_t id, int options, const char* call) {
  const int events = options & (WEXITED | WSTOPPED | WCONTINUED);
  if ((options & WNOHANG) || child_ready(idtype, id, events)) return ReadWait::proceed;
  Pidfds pidfds;
  if (idtype == P_PID)
    pidfds.add(static_cast<pid_t>(id));
  else
    for (const pid_t child : children()) pidfds.add(child);  // (a process group's others too: harmless)
  VirtualScheduler::Wait w;
  w.call = call;
  w.fds = pidfds.fds;
  // A child is another process: it ends by itself, or reports its own deadlock and ends. Whether
  // it waits on this one in turn is for run to see (Hooks::stuck): each child by its pidfd.
  w.outside = pidfds.missing || pidfds.fds.empty();
  w.ready = [&] { return child_ready(idtype, id, events); };
  w.recheck_ns = kChildRecheckNs;
  if (vt.wait(w) != VirtualScheduler::End::interrupted || child_ready(idtype, id, events)) return ReadWait::proceed;
  return signal_interrupts_blocking_call() ? ReadWait::interrupted : ReadWait::again;
}

ReadWait covered_child_wait(VirtualHostTime& vt, idtype_t idtype, id_t id, int options, const char* call) {
  Guard guard;
  try {
    return wait_for_child(vt, idtype, id, options, call);
  } catch (...) {
    return ReadWait::proceed;
  }
}

// waitpid's pid as waitid's idtype and id.
void waitpid_target(pid_t pid, idtype_t& idtype, id_t& id) {
  if (pid < -1) {
    idtype = P_PGID;
    id = static_cast<id_t>(-pid);
  } else if (pid == -1) {
    idtype = P_ALL;
    id = 0;
  } else if (pid == 0) {
    idtype = P_PGID;
    id = static_cast<id_t>(getpgrp());
  } else {
    idtype = P_PID;
    id = static_cast<id_t>(pid);
  }
}

// waitpid's options (WUNTRACED, WCONTINUED, WNOHANG) in waitid's terms: exits always count.
int waitid_options(int options) {
  return WEXITED | ((options & WUNTRACED) ? WSTOPPED : 0) | (options & (WCONTINUED | WNOHANG));
}

// Waits in virtual time for the child `pid` (waitpid's) selects; false: EINTR.
bool child_or_interrupted(VirtualHostTime* vt, pid_t pid, int options, const char* call) {
  if (!vt) return true;
  idtype_t idtype;
  id_t id;
  waitpid_target(pid, idtype, id);
  const int o = waitid_options(options);
  return readable_or_interrupted([&] { return covered_child_wait(*vt, idtype, id, o, call); });
}

}  // namespace

extern "C" {

__attribute__((visibility("default"))) pid_t waitpid(pid_t pid, int* status, int options) {
  if (!child_or_interrupted(virtual_time(), pid, options, "waitpid")) return -1;
  return real::waitpid(pid, status, options);
}

__attribute__((visibility("default"))) pid_t wait(int* status) {
  if (!child_or_interrupted(virtual_time(), -1, 0, "wait")) return -1;
  return real::waitpid(-1, status, 0);
}

__attribute__((visibility("default"))) pid_t wait3(int* status, int options, struct rusage* usage) {
  if (!child_or_interrupted(virtual_time(), -1, options, "wait3")) return -1;
  return real::wait4(-1, status, options, usage);
}

__attribute__((visibility("default"))) pid_t wait4(pid_t pid, int* status, int options, struct rusage* usage) {
  if (!child_or_interrupted(virtual_time(), pid, options, "wait4")) return -1;
  return real::wait4(pid, status, options, usage);
}

__attribute__((visibility("default"))) int waitid(idtype_t idtype, id_t id, siginfo_t* info, int options) {
  if (VirtualHostTime* vt = virtual_time())
    if (idtype == P_ALL || idtype == P_PID || idtype == P_PGID)
      if (!readable_or_interrupted([&] { return covered_child_wait(*vt, idtype, id, options, "waitid"); })) return -1;
  return real::waitid(idtype, id, info, options);
}

}  // extern "C"
