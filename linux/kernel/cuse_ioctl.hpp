// The spidev ioctls as a CUSE server must answer them. A CUSE driver cannot read the caller's
// memory: it asks the kernel to run the ioctl again with chosen ranges of that memory copied in
// (the argument, then the spi_ioc_transfer array, then every tx buffer) and chosen ranges to
// copy the answer out to (the rx buffers). This file decides, from what one call brought, the
// next step: "retry with these ranges" or "done, with this result and these bytes". It knows
// nothing of libfuse (linux/kernel/cuse_spidev.cpp drives it) so it is tested in process.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "linux/device_board.hpp"

namespace l6470emu {

/// A range of the calling process's memory.
struct CuseRange {
  std::uint64_t base = 0;
  std::size_t len = 0;
  bool operator==(const CuseRange&) const = default;
};

/// What a CUSE ioctl handler replies.
struct CuseIoctlStep {
  bool retry = false;              ///< ask the kernel to call again with `in` and `out`
  std::vector<CuseRange> in;       ///< retry: caller memory to copy in (concatenated, in order)
  std::vector<CuseRange> out;      ///< retry: caller memory the final answer is scattered over
  long result = 0;                 ///< done: the ioctl's return value, or -errno
  std::vector<std::uint8_t> data;  ///< done: the bytes for the `out` ranges of the last retry
};

/// The transport's limits on one retry (the kernel's fuse ioctl path).
struct CuseLimits {
  std::size_t max_ranges = 256;          ///< FUSE_IOCTL_MAX_IOV: in and out ranges together
  std::size_t max_bytes = 32 * 4096;     ///< per direction (fuse's max_pages x page size)
};

/// One call of a spidev node's ioctl handler: `cmd` as the caller passed it, `arg` its pointer
/// argument, `in` what the kernel copied in (the `in` ranges of the previous retry,
/// concatenated; empty on the first call) and `out_size` the room of the `out` ranges.
/// `bufsiz` is the node's bufsiz. SPI_IOC_MESSAGE(n) takes up to three calls (nothing → the
/// transfer array → the array and the tx data, run on `board`); the settings ioctls take two;
/// anything else is answered at once (-ENOTTY, as spidev does). A message the transport cannot
/// carry in one retry (more than `limits` allow) gets -ENOMEM, as the kernel's fuse path would.
CuseIoctlStep spidev_cuse_ioctl(DeviceBoard& board, std::uint64_t handle, std::uint32_t bufsiz, unsigned long cmd,
                                std::uint64_t arg, std::span<const std::uint8_t> in, std::size_t out_size,
                                const CuseLimits& limits = {});

}  // namespace l6470emu
