// The chips' GPIO lines on real gpiochips: for each emulated chip the daemon impersonates a
// CP2112 USB HID bridge through /dev/uhid; the stock kernel's hid-cp2112 driver binds to it and
// registers a gpiochip "cp2112_gpio" with 8 lines (0 BUSY, 1 FLAG, 2 SW, 3 STCK, 4 STBY_RST,
// 5 DIR (an L6474's; high on the others), 6 and 7 unused). Every get, set or direction change
// of a host program becomes a HID report answered from the DeviceBoard; edge events come from
// the driver polling the levels every 10 jiffies. Needs /dev/uhid (root, `modprobe uhid`) and the hid-cp2112 module.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "linux/device_board.hpp"
#include "linux/kernel/cuse_spidev.hpp"

namespace l6470emu {

/// Where one chip's lines appeared.
struct BridgeNode {
  std::size_t chain = 0;
  std::size_t chip = 0;
  std::string gpiochip;  ///< "/dev/gpiochip3" ("" when the kernel has not registered it)
};

/// All the bridges of a board, served by one thread until destroyed.
class UhidGpioBridges {
 public:
  UhidGpioBridges(DeviceBoard& board, NodeAccess access);
  ~UhidGpioBridges();
  UhidGpioBridges(const UhidGpioBridges&) = delete;
  UhidGpioBridges& operator=(const UhidGpioBridges&) = delete;

  /// Creates one bridge per chip of every chain and waits (up to 10 s) for the kernel's
  /// gpiochips. Returns "" or one line saying why not.
  std::string start();
  /// The gpiochip of every chip, in chain and chip order.
  const std::vector<BridgeNode>& nodes() const;
  /// HID reports answered so far (all bridges).
  std::size_t reports_answered() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace l6470emu
