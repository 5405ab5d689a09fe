// The emulated /dev and /sys entries.
#include "linux/preload/sysfs.hpp"

#include <dirent.h>
#include <sys/sysmacros.h>
#include <time.h>

#include <cstring>

#include "linux/preload/node_path.hpp"
#include "linux/preload/pwm_sysfs.hpp"
#include "linux/preload/real.hpp"
#include "linux/preload/state.hpp"

namespace l6470emu::preload {
namespace {

constexpr std::string_view kDevicesDir = "/sys/devices/l6470emu";

std::string dev_string(const DeviceNode& n) { return std::to_string(n.major) + ":" + std::to_string(n.minor); }

// Canonical sysfs directory of a node: /sys/devices/l6470emu/<name>.
std::string device_dir(const DeviceNode& n) { return std::string(kDevicesDir) + "/" + n.name; }

std::string subsystem_dir(const DeviceNode& n) {
  return n.type == DeviceNode::Type::gpiochip ? "/sys/bus/gpio" : "/sys/class/spidev";
}

// Paths that are symlinks to a node's device directory.
std::vector<std::string> link_paths(const DeviceNode& n) {
  std::vector<std::string> out;
  if (n.type == DeviceNode::Type::gpiochip)
    out.push_back("/sys/bus/gpio/devices/" + n.name);
  else
    out.push_back("/sys/class/spidev/" + n.name);
  out.push_back("/sys/dev/char/" + dev_string(n));
  return out;
}

std::string relative_target(std::string_view from_dir, const std::string& to) {
  // from_dir is an absolute directory; build "../../..." up to "/sys" then down to `to`.
  std::string up;
  std::size_t depth = 0;
  for (char c : from_dir.substr(std::strlen("/sys")))
    if (c == '/') ++depth;
  for (std::size_t i = 0; i < depth; ++i) up += "../";
  return up + to.substr(std::strlen("/sys/"));
}

std::string parent_of(std::string_view p) {
  const std::size_t s = p.rfind('/');
  return std::string(s == 0 ? std::string_view("/") : p.substr(0, s));
}

// Rewrites a path that goes through one of our symlinks into its canonical form.
std::string canonical(std::string_view path, bool follow_last) {
  std::string p(path);
  while (p.size() > 1 && p.back() == '/') p.pop_back();
  for (const DeviceNode& n : nodes())
    for (const std::string& link : link_paths(n)) {
      if (p == link) return follow_last ? device_dir(n) : p;
      if (p.size() > link.size() && p.compare(0, link.size(), link) == 0 && p[link.size()] == '/')
        p = device_dir(n) + p.substr(link.size());
    }
  if (follow_last)
    for (const DeviceNode& n : nodes())
      if (p == device_dir(n) + "/subsystem") return subsystem_dir(n);
  return p;
}

bool is_prefix_dir(std::string_view dir, std::string_view of) {
  return of.size() > dir.size() && of.compare(0, dir.size(), dir) == 0 && of[dir.size()] == '/';
}

}  // namespace

VirtualPath lookup_virtual(std::string_view path, bool follow) {
  VirtualPath v;
  if (!active() || path.empty() || path[0] != '/') return v;
  // /dev nodes, however the path spells them (the kernel's walk: node_path.hpp).
  int node = -1;
  const NodeWalk walk = walk_to_node(path, node);
  if (walk == NodeWalk::through_node) {
    v.type = VirtualPath::Type::not_directory;
    return v;
  }
  if (walk == NodeWalk::node) {
    const DeviceNode& n = nodes()[static_cast<std::size_t>(node)];
    v.type = VirtualPath::Type::char_device;
    v.major = n.major;
    v.minor = n.minor;
    v.node = node;
    return v;
  }
  if (path.size() < 5 || path.compare(0, 5, "/sys/") != 0) return v;
  if (path.compare(0, 14, "/sys/class/pwm") == 0)
    if (v = lookup_pwm(path); v.type != VirtualPath::Type::none) return v;
  const auto& ns = nodes();
  const std::string p = canonical(path, follow);
  for (const DeviceNode& n : ns) {
    for (const std::string& link : link_paths(n))
      if (p == link) {
        v.type = VirtualPath::Type::symlink;
        v.content = relative_target(parent_of(link), device_dir(n));
        return v;
      }
    const std::string dir = device_dir(n);
    if (p == dir) {
      v.type = VirtualPath::Type::directory;
      return v;
    }
    if (p == dir + "/dev") {
      v.type = VirtualPath::Type::file;
      v.content = dev_string(n) + "\n";
      return v;
    }
    if (p == dir + "/uevent") {
      v.type = VirtualPath::Type::file;
      v.content = "MAJOR=" + std::to_string(n.major) + "\nMINOR=" + std::to_string(n.minor) + "\nDEVNAME=" + n.name + "\n";
      return v;
    }
    if (p == dir + "/subsystem") {
      v.type = VirtualPath::Type::symlink;
      v.content = relative_target(dir, subsystem_dir(n));
      return v;
    }
    // Directories on the way to our entries that the real /sys may lack.
    for (const std::string& link : link_paths(n))
      if (is_prefix_dir(p, link) || p == parent_of(link)) {
        if (real::access(p.c_str(), F_OK) != 0) {
          v.type = VirtualPath::Type::directory;
          return v;
        }
      }
    if (p == subsystem_dir(n) || p == std::string(kDevicesDir) || p == "/sys/bus/gpio/devices" || p == "/sys/dev/char") {
      if (real::access(p.c_str(), F_OK) != 0) {
        v.type = VirtualPath::Type::directory;
        return v;
      }
    }
  }
  return v;
}

std::string virtual_realpath(std::string_view path) {
  const VirtualPath v = lookup_virtual(path, true);
  if (v.type == VirtualPath::Type::none || v.type == VirtualPath::Type::not_directory) return {};
  if (v.type == VirtualPath::Type::char_device) return nodes()[static_cast<std::size_t>(v.node)].path;
  return canonical(path, true);
}

std::vector<std::pair<std::string, unsigned char>> virtual_dir_entries(std::string_view dir) {
  std::vector<std::pair<std::string, unsigned char>> out;
  if (!active()) return out;
  std::string d(dir);
  while (d.size() > 1 && d.back() == '/') d.pop_back();
  for (const DeviceNode& n : nodes()) {
    if (parent_of(n.path) == d) out.emplace_back(n.path.substr(n.path.rfind('/') + 1), DT_CHR);
    for (const std::string& link : link_paths(n))
      if (parent_of(link) == d) out.emplace_back(link.substr(link.rfind('/') + 1), DT_LNK);
    if (d == kDevicesDir) out.emplace_back(n.name, DT_DIR);
  }
  if (d.compare(0, 14, "/sys/class/pwm") == 0)
    for (auto& e : pwm_dir_entries(d)) out.push_back(std::move(e));
  if (d == "/sys/class" && !pwm_dir_entries("/sys/class/pwm").empty()) out.emplace_back("pwm", DT_DIR);
  return out;
}

void fill_stat(const VirtualPath& v, struct stat* st) {
  std::memset(st, 0, sizeof *st);
  timespec now{};
  clock_gettime(CLOCK_REALTIME, &now);
  st->st_atim = st->st_mtim = st->st_ctim = now;
  st->st_nlink = 1;
  st->st_blksize = 4096;
  st->st_dev = makedev(0, 5);
  st->st_ino = 0x6470'0000u + static_cast<unsigned>(v.node + 1) * 16 + static_cast<unsigned>(v.type);
  switch (v.type) {
    case VirtualPath::Type::char_device:
      st->st_mode = S_IFCHR | 0660;
      st->st_rdev = makedev(v.major, v.minor);
      break;
    case VirtualPath::Type::directory:
      st->st_mode = S_IFDIR | 0755;
      st->st_nlink = 2;
      break;
    case VirtualPath::Type::file:
      st->st_mode = S_IFREG | (v.mode ? v.mode : 0444);
      st->st_size = 4096;  // sysfs attributes report a page
      break;
    case VirtualPath::Type::symlink:
      st->st_mode = S_IFLNK | 0777;
      st->st_size = static_cast<off_t>(v.content.size());
      break;
    case VirtualPath::Type::none:
    case VirtualPath::Type::not_directory:
      break;
  }
}

}  // namespace l6470emu::preload
