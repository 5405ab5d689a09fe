// `serve --cuse --uhid`: the kernel's own device nodes for the daemon's board (CUSE spidev
// nodes, CP2112 gpiochips through UHID) and the --node-owner/--node-group/--node-mode options.
#pragma once

#include <string>

#include "linux/kernel/cuse_spidev.hpp"
#include "linux/serve/daemon.hpp"

namespace l6470emu {

/// Parses the node options: a user and a group (name or number) and an octal mode up to 0777.
/// Returns "" or one line naming the bad value.
std::string parse_node_access(const std::string& owner, const std::string& group, const std::string& mode,
                              NodeAccess& access);

/// The daemon front end that creates the CUSE spidev nodes (`cuse`) and the UHID gpiochips
/// (`uhid`) of its board, and prints where each appeared.
FrontEnds kernel_front_ends(bool cuse, bool uhid, NodeAccess access);

}  // namespace l6470emu
