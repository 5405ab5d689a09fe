// /dev/spidevB.C served by the kernel: a CUSE character device (libfuse3's cuse_lowlevel) whose
// open files are handles of a DeviceBoard, exactly like the preload's, so kernel clients and preload
// clients share one board, one bus clock and one set of spidev rules. Needs /dev/cuse (root,
// `modprobe cuse`).
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <memory>
#include <string>

#include "linux/device_board.hpp"

namespace l6470emu {

/// Owner, group and mode of the device nodes the daemon creates in /dev.
struct NodeAccess {
  uid_t owner = 0;
  gid_t group = 0;
  mode_t mode = 0660;
};

/// One CUSE spidev node, served by its own threads until destroyed.
class CuseSpidev {
 public:
  /// Prepares node `device` of `board` (a spidev node: "/dev/spidev0.0").
  CuseSpidev(DeviceBoard& board, std::size_t device, NodeAccess access);
  ~CuseSpidev();
  CuseSpidev(const CuseSpidev&) = delete;
  CuseSpidev& operator=(const CuseSpidev&) = delete;

  /// Registers the device with the kernel and starts serving it; returns when the node exists
  /// in /dev with its owner and mode, or "" replaced by one line saying why it cannot.
  std::string start();
  /// The character device's major:minor once started ("245:0").
  std::string device_number() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace l6470emu
