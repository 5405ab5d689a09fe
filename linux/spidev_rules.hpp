// The Linux spidev driver's rules (drivers/spi/spidev.c and spi_setup/__spi_validate in
// drivers/spi/spi.c, Linux 6.1), applied to an emulated device: settings ioctls, message
// validation with the kernel's error codes, and word/bit order on the wire. No OS calls;
// user memory has already been copied in by the transport.
#pragma once

#include <linux/spi/spidev.h>

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "core/tick.hpp"
#include "spi/message.hpp"
#include "spi/spi_device.hpp"
#include "spi/wire.hpp"

namespace l6470emu {

/// Character-device major of spidev (what stat reports for /dev/spidevB.C).
inline constexpr unsigned kSpidevMajor = 153;

/// spidev's SPI_MODE_MASK: the mode bits user space may read and write.
inline constexpr std::uint32_t kSpidevModeMask =
    SPI_CPHA | SPI_CPOL | SPI_CS_HIGH | SPI_LSB_FIRST | SPI_3WIRE | SPI_LOOP | SPI_NO_CS | SPI_READY |
    SPI_TX_DUAL | SPI_TX_QUAD | SPI_TX_OCTAL | SPI_RX_DUAL | SPI_RX_QUAD | SPI_RX_OCTAL | SPI_RX_CPHA_FLIP;

/// Mode bits the emulated controller supports (others: EINVAL from spi_setup, except the
/// dual/quad/octal ones, which spi_setup drops silently).
inline constexpr std::uint32_t kControllerModeBits = SPI_CPHA | SPI_CPOL | SPI_CS_HIGH | SPI_LSB_FIRST;

/// Fastest SCK of the emulated controller; faster requests are clamped to it, as spi.c does.
inline constexpr std::uint32_t kControllerMaxSpeedHz = 125'000'000;

/// Slowest SCK of the emulated controller. A controller whose fastest clock is 125 MHz (a 250 MHz
/// clock halved, the BCM2835's) divides that clock by at most 65536, so it cannot go below
/// 250 MHz / 65536 = 3814.7 Hz. spi.c's __spi_validate refuses a transfer slower than the
/// controller's min_speed_hz with -EINVAL (Linux 6.1; drivers that declare one, e.g.
/// spi-sun4i/spi-sun6i at 3 kHz, spi-omap2-mcspi at its reference clock / 32768), and so does
/// the emulator, whatever the setting's source: SPI_IOC_WR_MAX_SPEED_HZ (which spidev accepts),
/// a transfer's speed_hz or the description's speed=.
inline constexpr std::uint32_t kControllerMinSpeedHz = 3815;

/// The settings the kernel keeps per spidev device (shared by every open file).
struct SpidevSettings {
  std::uint32_t mode = 0;           ///< spi->mode (SPI_MODE_USER_MASK bits)
  std::uint8_t bits_per_word = 8;   ///< spi->bits_per_word
  std::uint32_t max_speed_hz = 0;   ///< spi->max_speed_hz, from the device tree (config speed=)
  std::uint32_t speed_hz = 0;       ///< spidev->speed_hz: default speed of transfers, reset at last close
  std::uint32_t bufsiz = 4096;      ///< spidev bufsiz module parameter
};

/// Result of an ioctl: the return value (>= 0) or -errno.
using IoctlResult = long;

/// Whether `bits` is a word size the emulated controller supports (8, 16, 32).
constexpr bool controller_supports_bits(unsigned bits) { return bits == 8 || bits == 16 || bits == 32; }

/// Whether `cmd` is one of spidev's settings ioctls (exactly: the size and direction too).
/// spidev answers any other command but SPI_IOC_MESSAGE(n) with -ENOTTY before it touches the
/// caller's memory.
bool is_spidev_settings_ioctl(unsigned long cmd);

/// SPI_IOC_RD_* / SPI_IOC_WR_* except SPI_IOC_MESSAGE: reads or changes `s` as spidev does.
/// `value` is the (already copied) argument; reads store into it. Returns 0 or -errno
/// (-ENOTTY for a command that is not a spidev settings ioctl).
IoctlResult spidev_settings_ioctl(SpidevSettings& s, unsigned long cmd, std::uint32_t& value);

/// Whether `cmd` is SPI_IOC_MESSAGE(n) for some n (n may be 0); sets n.
bool is_spi_message_ioctl(unsigned long cmd, std::size_t& n);

/// spidev_message's first loop, before any user memory is copied: -EMSGSIZE when the tx or
/// rx data (each transfer rounded up to 8 bytes) exceeds `bufsiz`, or the total exceeds INT_MAX.
/// Returns the total length in bytes or -EMSGSIZE. Every transport checks this before it copies.
IoctlResult spidev_message_sizes(std::uint32_t bufsiz, std::span<const spi_ioc_transfer> xfers);

/// spidev_message's and __spi_validate's checks on a message, before anything is clocked:
/// -EMSGSIZE past bufsiz (or past INT_MAX in total), -EINVAL for word sizes, lengths, nbits
/// and speeds (below kControllerMinSpeedHz) the controller cannot do. Returns the total length
/// in bytes or -errno.
IoctlResult validate_spidev_message(const SpidevSettings& s, std::span<const spi_ioc_transfer> xfers);

/// Bytes of tx data the transport must copy for `xfers` (sum of len over transfers with a tx_buf).
std::size_t spidev_tx_bytes(std::span<const spi_ioc_transfer> xfers);
/// Bytes of rx data a message produces (sum of len over transfers with an rx_buf).
std::size_t spidev_rx_bytes(std::span<const spi_ioc_transfer> xfers);

/// The wire settings of `s` (mode, bit order, CS polarity, word size, speed) as the bus sees them.
WireSettings spidev_wire_settings(const SpidevSettings& s);

/// Runs a validated message on `dev` with spi_sync's chip-select rules (run_message), charging
/// word_delay_usecs, delay_usecs and a 10 us CS-high time between cs_change transfers like the
/// kernel. `tx` holds the tx data of the transfers that have a tx_buf, concatenated; `rx`
/// receives the rx data of those with an rx_buf. Words (bits_per_word 16/32, little-endian host)
/// go to the bus as bytes in the order the controller shifts them; the mode, the bit order and
/// the CS polarity are the bus's business (spidev_wire_settings, BusTiming::wire): `dev` is the
/// board's bus begun with the same settings.
void run_spidev_message(SpiDevice& dev, const SpidevSettings& s, std::span<const spi_ioc_transfer> xfers,
                        std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx);

/// A validated spidev message as the wire carries it (run_spidev_message's steps, apart): its
/// bytes in wire order and the transfers run_message clocks, which can be clocked a piece at a
/// time (a caller that may die while its message is on the bus) with the chip seeing exactly what
/// it sees when they are clocked at once: the same bytes at the same ticks, CS falling and rising
/// where it would. Reusable: prepare() keeps the buffers' capacity.
class SpidevWireMessage {
 public:
  /// Takes the message (`xfers` and its concatenated `tx` data, which must outlive the message's
  /// use) into wire order. Nothing is clocked yet.
  void prepare(const SpidevSettings& s, std::span<const spi_ioc_transfer> xfers, std::span<const std::uint8_t> tx);
  /// Ticks the whole message takes on the bus (bytes, word delays, delays, CS-high times).
  Tick bus_ticks() const;
  /// Clocks on `dev` from where the last call stopped, about `budget` ticks of bus time (whole
  /// bytes, at least one; kNever: all the rest). Returns true when the message is all clocked.
  bool run(SpiDevice& dev, Tick budget);
  /// Gives up the rest of the message: nothing more is clocked, and CS rises now if it is held
  /// (as when a controller stops mid-message).
  void abandon(SpiDevice& dev);
  /// Copies what was received into `rx` (the rx data of the transfers with an rx_buf, in host order).
  void finish(std::span<std::uint8_t> rx) const;

 private:
  bool raises_after(std::size_t i) const;

  SpidevSettings settings_;
  std::span<const spi_ioc_transfer> xfers_;
  BusTiming timing_;
  std::vector<std::uint8_t> wire_tx_, wire_rx_;
  std::vector<SpiTransfer> transfers_, piece_;
  std::size_t next_ = 0;             // the transfer clocked next
  std::uint32_t done_in_next_ = 0;   // its bytes clocked already
  bool cs_high_mode_ = false;        // SPI_CS_HIGH: the chip is never selected, only time passes
  Tick cs_high_left_ = 0;            // SPI_CS_HIGH: bus time still to pass
  Tick bus_ticks_ = 0;               // SPI_CS_HIGH: the whole message's
};

}  // namespace l6470emu
