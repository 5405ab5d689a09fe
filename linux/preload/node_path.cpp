// The kernel's path walk over the emulated nodes, lexically, with real checks only under /dev.
#include "linux/preload/node_path.hpp"

#include <fcntl.h>
#include <limits.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstring>
#include <vector>

#include "linux/preload/real.hpp"
#include "linux/preload/state.hpp"

namespace l6470emu::preload {
namespace {

bool starts_with(std::string_view s, std::string_view prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

/// No empty, '.' or '..' component and no trailing '/': the kernel's walk is the text itself.
bool canonical(std::string_view p) {
  if (p.size() > 1 && p.back() == '/') return false;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p[i] != '/') continue;
    const std::string_view rest = p.substr(i + 1);
    if (starts_with(rest, "/")) return false;
    if (rest == "." || starts_with(rest, "./") || rest == ".." || starts_with(rest, "../")) return false;
  }
  return true;
}

/// Index of the node at exactly `p`, or -1.
int node_at(std::string_view p) {
  if (!starts_with(p, "/dev/")) return -1;
  const auto& ns = nodes();
  for (std::size_t i = 0; i < ns.size(); ++i)
    if (ns[i].path == p) return static_cast<int>(i);
  return -1;
}

/// Splits "/a//b/" into "a", "", "b", "" (the components after the leading '/').
std::vector<std::string_view> components(std::string_view p) {
  std::vector<std::string_view> out;
  std::size_t i = 1;
  for (;;) {
    const std::size_t j = p.find('/', i);
    out.push_back(p.substr(i, j == std::string_view::npos ? std::string_view::npos : j - i));
    if (j == std::string_view::npos) break;
    i = j + 1;
  }
  return out;
}

}  // namespace

bool may_be_device_path(const char* path) {
  if (!path || path[0] != '/') return false;
  if (std::strncmp(path, "/dev/", 5) == 0 || std::strncmp(path, "/sys/", 5) == 0) return true;
  return !canonical(path);
}

NodeWalk walk_to_node(std::string_view path, int& node) {
  node = -1;
  if (path.empty() || path[0] != '/') return NodeWalk::not_ours;
  if (canonical(path)) {
    if (!starts_with(path, "/dev/")) return NodeWalk::not_ours;
    node = node_at(path);
    if (node >= 0) return NodeWalk::node;
    // A component after a node's name: /dev/spidev0.0/x.
    for (const auto& n : nodes())
      if (path.size() > n.path.size() && starts_with(path, n.path) && path[n.path.size()] == '/')
        return NodeWalk::through_node;
    return NodeWalk::not_ours;
  }
  const std::vector<std::string_view> parts = components(path);
  // Lexically first, without a system call: only a walk that passes under /dev/ is done again.
  {
    std::string cur;
    bool under_dev = false;
    for (std::string_view c : parts) {
      if (c.empty() || c == ".") continue;
      if (c == "..") {
        cur.resize(cur.empty() ? 0 : cur.rfind('/'));
      } else {
        cur += '/';
        cur += c;
      }
      under_dev = under_dev || starts_with(cur, "/dev/");
    }
    if (!under_dev) return NodeWalk::not_ours;
  }
  std::string cur;  // "" is the root
  int at = -1;      // the node `cur` names
  for (std::string_view c : parts) {
    if (at >= 0) return NodeWalk::through_node;  // anything after a node, even "" or "."
    if (c.empty() || c == ".") continue;
    if (c == "..") {
      if (cur.empty()) continue;  // "/.." is "/"
      struct stat st{};
      if (real::lstat(cur.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) return NodeWalk::not_ours;
      cur.resize(cur.rfind('/'));
      continue;
    }
    cur += '/';
    cur += c;
    at = node_at(cur);
  }
  if (at < 0) return NodeWalk::not_ours;
  node = at;
  return NodeWalk::node;
}

std::string absolute_path(int dirfd, const char* path) {
  if (!path) return {};
  if (path[0] == '/') return path;
  if (path[0] == '\0') return {};
  char dir[PATH_MAX];
  long n = 0;
  if (dirfd == AT_FDCWD) {
    n = syscall(SYS_getcwd, dir, sizeof dir);  // the length with its terminating NUL
    if (n <= 0) return {};
    n = static_cast<long>(std::strlen(dir));
  } else {
    const std::string link = "/proc/self/fd/" + std::to_string(dirfd);
    n = syscall(SYS_readlinkat, AT_FDCWD, link.c_str(), dir, sizeof dir - 1);
    if (n <= 0) return {};
    dir[n] = '\0';
  }
  if (dir[0] != '/') return {};  // "(unreachable)" or a descriptor that is not a directory
  std::string out(dir, static_cast<std::size_t>(n));
  if (out.back() != '/') out += '/';
  return out + path;
}

}  // namespace l6470emu::preload
