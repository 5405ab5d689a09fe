// The Linux front's check of a board description against this machine: a chain's path= is taken
// over in host programs (the preload) or made a node (CUSE), so what already exists there must be
// a spidev node. Not here: the description's own rules (board/board_config.hpp, no OS calls).
#pragma once

#include <string>
#include <string_view>

#include "board/board_config.hpp"

namespace l6470emu {

/// What already exists at `path` and is not a spidev node, as words for a message ("an existing
/// character device (10:232, 'kvm') of another driver", "an existing regular file", ...), or ""
/// when nothing is there or a spidev node is: the kernel's (character major 153) or one the
/// kernel names spidev* (a kernel-node daemon's CUSE node).
std::string existing_non_spidev(const std::string& path);

/// Checks every chain's path of `config`: "" when each is free or a spidev node, else one line
/// "l6470emu: config ORIGIN: chain N (bus=B cs=C): path 'P' is ..., not a spidev node: ...".
std::string check_device_paths(const BoardConfig& config, std::string_view origin);

}  // namespace l6470emu
