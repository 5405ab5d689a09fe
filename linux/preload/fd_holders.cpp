// Who holds a pipe (linux/preload/fd_holders.hpp): the /proc/PID/fd links of every process read,
// as lsof does. A process whose descriptors cannot be read (another user's) cannot hold an end
// of our pipe either: it would have had to inherit it or be sent it, and then it is ours. A
// process with a child is left alone: the child's end may come as a signal that writes the pipe.
#include "linux/preload/fd_holders.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "linux/preload/real.hpp"
#include "linux/unix_socket_diag.hpp"

namespace l6470emu::preload {

std::string link_of(const std::string& path) {
  char buf[4096];
  const ssize_t n = real::readlink(path.c_str(), buf, sizeof buf - 1);
  return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
}

namespace {

bool is_number(const char* s) {
  if (!*s) return false;
  for (; *s; ++s)
    if (*s < '0' || *s > '9') return false;
  return true;
}

// Whether process `pid` is a child of `self` (its exit sends a SIGCHLD, whose handler may write
// the pipe: the self-pipe of an event loop).
bool is_child_of(const char* pid, const std::string& self) {
  const std::string path = std::string("/proc/") + pid + "/stat";
  const int fd = real::open(path.c_str(), O_RDONLY | O_CLOEXEC, 0);
  if (fd < 0) return false;
  char buf[512];
  const ssize_t n = real::read(fd, buf, sizeof buf - 1);
  real::close(fd);
  if (n <= 0) return false;
  buf[n] = 0;
  const char* close_paren = std::strrchr(buf, ')');  // the name may hold blanks and parentheses
  if (!close_paren) return false;
  char state = 0;
  long ppid = 0;
  return std::sscanf(close_paren + 1, " %c %ld", &state, &ppid) == 2 && std::to_string(ppid) == self;
}

// Whether process `pid`'s descriptors include one of `targets` ("pipe:[123]").
bool holds(const char* pid, const std::vector<std::string>& targets) {
  const std::string dir = std::string("/proc/") + pid + "/fd";
  DIR* d = real::opendir(dir.c_str());
  if (!d) return false;
  bool found = false;
  while (const dirent* e = real::readdir(d))
    if (is_number(e->d_name)) {
      const std::string link = link_of(dir + "/" + e->d_name);
      if (std::find(targets.begin(), targets.end(), link) != targets.end()) {
        found = true;
        break;
      }
    }
  real::closedir(d);
  return found;
}

// Whether no other process holds any of `targets`, and this one has no child.
bool held_by_this_process_alone(const std::vector<std::string>& targets) {
  const std::string self = std::to_string(getpid());
  DIR* d = real::opendir("/proc");
  if (!d) return false;
  bool alone = true;
  while (const dirent* e = real::readdir(d))
    if (is_number(e->d_name) && self != e->d_name && (holds(e->d_name, targets) || is_child_of(e->d_name, self))) {
      alone = false;
      break;
    }
  real::closedir(d);
  return alone;
}

}  // namespace

bool pipe_held_by_this_process_alone(int fd) {
  const std::string target = link_of("/proc/self/fd/" + std::to_string(fd));
  if (target.rfind("pipe:[", 0) != 0) return false;
  return held_by_this_process_alone({target});
}

bool socket_pair_held_by_this_process_alone(int fd) {
  const std::string target = link_of("/proc/self/fd/" + std::to_string(fd));
  if (target.rfind("socket:[", 0) != 0) return false;
  const unsigned long peer = unix_socket_info(std::strtoul(target.c_str() + 8, nullptr, 10)).peer;
  if (peer == 0) return false;
  return held_by_this_process_alone({target, "socket:[" + std::to_string(peer) + "]"});
}

}  // namespace l6470emu::preload
