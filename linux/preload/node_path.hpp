// How the kernel's path walk meets the emulated device nodes: every spelling that reaches a node
// (//dev/spidev0.0, /dev/./spidev0.0, /dev/../dev/spidev0.0, a path relative to a directory) and
// every path that goes on past one (/dev/spidev0.0/, /dev/spidev0.0/x: ENOTDIR). Not here: what
// opening or stat-ing a node does (intercept_open.cpp, intercept_stat.cpp).
#pragma once

#include <string>
#include <string_view>

namespace l6470emu::preload {

/// What the walk of a path meets.
enum class NodeWalk {
  not_ours,      ///< no emulated node on the way: the real file system answers
  node,          ///< the path names an emulated node
  through_node,  ///< the path goes on past an emulated node (a trailing '/', '.', a name): ENOTDIR
};

/// Cheap test, no system call and no daemon contact: whether absolute `path` may reach an emulated
/// /dev node or a /sys entry at all (it starts with /dev/ or /sys/, or is spelt non-canonically).
bool may_be_device_path(const char* path);

/// Walks absolute `path` over the emulated nodes. A path spelt canonically is compared as it
/// is; any other is resolved lexically ('//' and '.' dropped, '..' taken back) and, when that
/// reaches /dev, walked again checking that each directory a '..' leaves is a real directory
/// (not a symbolic link, which the kernel would follow instead). Sets `node` for NodeWalk::node.
/// Call it inside the preload's Guard (it may contact the daemon for the node list).
NodeWalk walk_to_node(std::string_view path, int& node);

/// The absolute path of `path` as openat(dirfd, path) would see it (the current directory for
/// AT_FDCWD, /proc/self/fd/DIRFD otherwise): `path` itself when absolute, "" when it cannot be told.
std::string absolute_path(int dirfd, const char* path);

}  // namespace l6470emu::preload
