// Where the preload library sends what host programs do to emulated files: a DeviceBoard inside
// the process (LocalBackend) or `l6470emu serve` over its socket (RemoteBackend).
#pragma once

#include <errno.h>
#include <linux/spi/spidev.h>

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "linux/device_board.hpp"

namespace l6470emu::preload {

/// The board as the preload library sees it. Every call returns >= 0 or -errno and never throws.
class Backend {
 public:
  virtual ~Backend() = default;
  /// The device nodes (empty when the daemon could not be reached).
  virtual const std::vector<DeviceNode>& nodes() = 0;
  virtual NewFile open(std::size_t device, bool cloexec) = 0;
  virtual void closed(std::uint64_t handle) = 0;
  virtual long ioctl(std::uint64_t handle, unsigned long cmd, std::span<std::uint8_t> arg, NewFile* created,
                     bool cloexec_created) = 0;
  virtual long spi_message(std::uint64_t handle, std::span<const spi_ioc_transfer> xfers,
                           std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) = 0;
  virtual long spi_read(std::uint64_t handle, std::span<std::uint8_t> rx) = 0;
  virtual long spi_write(std::uint64_t handle, std::span<const std::uint8_t> tx) = 0;
  /// The kernel's pwm sysfs class (DeviceBoard::pwm_write; the files: pwm_sysfs.hpp): how many
  /// pwmchips there are (pwmchipN is chain N). The default: none.
  virtual std::size_t pwm_chips() { return 0; }
  /// Channels of pwmchip `chain` (its chips).
  virtual std::size_t pwm_channels(std::size_t) { return 0; }
  /// A write to a pwm attribute: the bytes taken or -errno (DeviceBoard::pwm_write).
  virtual long pwm_write(std::size_t, int, PwmAttr, std::string_view) { return -ENODEV; }
  /// A read of a pwm attribute: 0 and `out`, or -errno (DeviceBoard::pwm_read).
  virtual long pwm_read(std::size_t, int, PwmAttr, std::string&) { return -ENODEV; }
  /// fork() hooks: hold every lock in prepare, release in parent/child (the child also drops
  /// what did not survive the fork: the pump thread, the daemon connection).
  virtual void before_fork() = 0;
  virtual void after_fork_parent() = 0;
  virtual void after_fork_child() = 0;
};

/// The emulator inside the host process.
std::unique_ptr<Backend> make_local_backend(const BoardConfig& config);
/// A connection to `l6470emu serve` at `socket_path`.
std::unique_ptr<Backend> make_remote_backend(const std::string& socket_path, const std::string& log);

}  // namespace l6470emu::preload
