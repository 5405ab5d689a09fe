// spidev settings, message validation and wire order, as drivers/spi/spidev.c and spi.c do them.
#include "linux/spidev_rules.hpp"

#include <asm/ioctl.h>
#include <cerrno>
#include <climits>
#include <vector>

#include "spi/message.hpp"

namespace l6470emu {
namespace {

constexpr std::uint32_t kUglyBits = SPI_TX_DUAL | SPI_TX_QUAD | SPI_TX_OCTAL | SPI_RX_DUAL | SPI_RX_QUAD | SPI_RX_OCTAL;
constexpr std::uint32_t kModeUserMask = (1u << 17) - 1;  // SPI_MODE_USER_MASK
constexpr std::uint32_t kKmallocMinAlign = 8;            // ARCH_KMALLOC_MINALIGN on x86-64

// spi_setup(): the controller's mode bits, dual/quad bits dropped with a warning.
IoctlResult spi_setup_mode(std::uint32_t& mode) {
  std::uint32_t bad = mode & ~(kControllerModeBits | SPI_CS_WORD);
  const std::uint32_t ugly = bad & kUglyBits;
  mode &= ~ugly;
  bad &= ~ugly;
  return bad ? -EINVAL : 0;
}

unsigned word_bytes(unsigned bits) { return bits <= 8 ? 1 : bits <= 16 ? 2 : 4; }

// Host memory (words in little-endian order) -> bytes in the order the controller shifts them,
// and back: MSB first, a word goes out from its most significant byte; LSB first, from its least
// significant one (each byte's bit order is the bus's business).
void to_wire(const std::uint8_t* host, std::uint8_t* wire, std::size_t len, unsigned w, bool lsb_first) {
  for (std::size_t i = 0; i < len; i += w)
    for (unsigned k = 0; k < w; ++k) wire[i + k] = lsb_first ? host[i + k] : host[i + (w - 1 - k)];
}
void from_wire(const std::uint8_t* wire, std::uint8_t* host, std::size_t len, unsigned w, bool lsb_first) {
  for (std::size_t i = 0; i < len; i += w)
    for (unsigned k = 0; k < w; ++k) (lsb_first ? host[i + k] : host[i + (w - 1 - k)]) = wire[i + k];
}

}  // namespace

bool is_spidev_settings_ioctl(unsigned long cmd) {
  switch (cmd) {
    case SPI_IOC_RD_MODE: case SPI_IOC_WR_MODE: case SPI_IOC_RD_MODE32: case SPI_IOC_WR_MODE32:
    case SPI_IOC_RD_LSB_FIRST: case SPI_IOC_WR_LSB_FIRST: case SPI_IOC_RD_BITS_PER_WORD:
    case SPI_IOC_WR_BITS_PER_WORD: case SPI_IOC_RD_MAX_SPEED_HZ: case SPI_IOC_WR_MAX_SPEED_HZ:
      return true;
    default:
      return false;
  }
}

IoctlResult spidev_settings_ioctl(SpidevSettings& s, unsigned long cmd, std::uint32_t& value) {
  switch (cmd) {
    case SPI_IOC_RD_MODE:
      value = s.mode & kSpidevModeMask & 0xFF;
      return 0;
    case SPI_IOC_RD_MODE32:
      value = s.mode & kSpidevModeMask;
      return 0;
    case SPI_IOC_RD_LSB_FIRST:
      value = (s.mode & SPI_LSB_FIRST) ? 1 : 0;
      return 0;
    case SPI_IOC_RD_BITS_PER_WORD:
      value = s.bits_per_word;
      return 0;
    case SPI_IOC_RD_MAX_SPEED_HZ:
      value = s.speed_hz;
      return 0;
    case SPI_IOC_WR_MODE:
    case SPI_IOC_WR_MODE32: {
      std::uint32_t tmp = cmd == SPI_IOC_WR_MODE ? (value & 0xFF) : value;
      if (tmp & ~kSpidevModeMask) return -EINVAL;
      tmp |= s.mode & ~kSpidevModeMask;
      std::uint32_t mode = tmp & kModeUserMask;
      const IoctlResult r = spi_setup_mode(mode);
      if (r == 0) s.mode = mode;
      return r;
    }
    case SPI_IOC_WR_LSB_FIRST: {
      std::uint32_t mode = (value & 0xFF) ? (s.mode | SPI_LSB_FIRST) : (s.mode & ~std::uint32_t{SPI_LSB_FIRST});
      const IoctlResult r = spi_setup_mode(mode);
      if (r == 0) s.mode = mode;
      return r;
    }
    case SPI_IOC_WR_BITS_PER_WORD: {
      const unsigned bits = value & 0xFF;
      if (bits == 0) {
        s.bits_per_word = 8;  // spi_setup: 0 means 8
        return 0;
      }
      if (!controller_supports_bits(bits)) return -EINVAL;
      s.bits_per_word = static_cast<std::uint8_t>(bits);
      return 0;
    }
    case SPI_IOC_WR_MAX_SPEED_HZ:
      if (value == 0) return -EINVAL;
      s.speed_hz = value;  // spidev keeps what was asked; transfers are clamped to the controller
      return 0;
    default:
      return -ENOTTY;
  }
}

bool is_spi_message_ioctl(unsigned long cmd, std::size_t& n) {
  if (_IOC_TYPE(cmd) != SPI_IOC_MAGIC || _IOC_NR(cmd) != _IOC_NR(SPI_IOC_MESSAGE(0)) || _IOC_DIR(cmd) != _IOC_WRITE)
    return false;
  n = _IOC_SIZE(cmd) / sizeof(spi_ioc_transfer);
  return true;
}

IoctlResult spidev_message_sizes(std::uint32_t bufsiz, std::span<const spi_ioc_transfer> xfers) {
  std::uint64_t total = 0, tx_total = 0, rx_total = 0;
  for (const auto& x : xfers) {
    const std::uint64_t aligned = (std::uint64_t{x.len} + kKmallocMinAlign - 1) / kKmallocMinAlign * kKmallocMinAlign;
    total += x.len;
    if (total > INT_MAX || x.len > INT_MAX) return -EMSGSIZE;
    if (x.rx_buf) {
      rx_total += aligned;
      if (rx_total > bufsiz) return -EMSGSIZE;
    }
    if (x.tx_buf) {
      tx_total += aligned;
      if (tx_total > bufsiz) return -EMSGSIZE;
    }
  }
  return static_cast<IoctlResult>(total);
}

IoctlResult validate_spidev_message(const SpidevSettings& s, std::span<const spi_ioc_transfer> xfers) {
  const IoctlResult total = spidev_message_sizes(s.bufsiz, xfers);
  if (total < 0) return total;
  // __spi_validate
  if (xfers.empty()) return -EINVAL;
  for (const auto& x : xfers) {
    const unsigned bits = x.bits_per_word ? x.bits_per_word : s.bits_per_word;
    if (!controller_supports_bits(bits)) return -EINVAL;
    if (x.len % word_bytes(bits)) return -EINVAL;
    if (x.tx_buf && x.tx_nbits != 0 && x.tx_nbits != 1) return -EINVAL;  // dual/quad need SPI_TX_DUAL/QUAD
    if (x.rx_buf && x.rx_nbits != 0 && x.rx_nbits != 1) return -EINVAL;
  }
  return total;
}

std::size_t spidev_tx_bytes(std::span<const spi_ioc_transfer> xfers) {
  std::size_t n = 0;
  for (const auto& x : xfers)
    if (x.tx_buf) n += x.len;
  return n;
}

std::size_t spidev_rx_bytes(std::span<const spi_ioc_transfer> xfers) {
  std::size_t n = 0;
  for (const auto& x : xfers)
    if (x.rx_buf) n += x.len;
  return n;
}

void run_spidev_message(SpiDevice& dev, const SpidevSettings& s, std::span<const spi_ioc_transfer> xfers,
                        std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  thread_local std::vector<std::uint8_t> wire_tx, wire_rx;
  thread_local std::vector<SpiTransfer> transfers;
  // Wire buffers for the transfers that have a buffer; bufferless ones (zeros out, nothing in)
  // need none, however long they are.
  std::size_t total = 0;
  for (const auto& x : xfers)
    if (x.tx_buf || x.rx_buf) total += x.len;
  wire_tx.assign(total, 0);
  wire_rx.assign(total, 0);
  const bool lsb_first = (s.mode & SPI_LSB_FIRST) != 0;

  std::size_t off = 0, tx_off = 0;
  for (const auto& x : xfers) {
    const unsigned w = word_bytes(x.bits_per_word ? x.bits_per_word : s.bits_per_word);
    if (x.tx_buf) {
      to_wire(tx.data() + tx_off, wire_tx.data() + off, x.len, w, lsb_first);
      tx_off += x.len;
    }
    if (x.tx_buf || x.rx_buf) off += x.len;
  }

  BusTiming timing;
  timing.default_speed_hz = s.speed_hz ? s.speed_hz : s.max_speed_hz;
  timing.cs_high_ticks = ticks_from_us(10);  // spi.c's default cs_change delay
  timing.wire = spidev_wire_settings(s);
  auto speed_of = [&](const spi_ioc_transfer& x) {
    std::uint32_t hz = x.speed_hz ? x.speed_hz : s.speed_hz;
    if (hz == 0) hz = s.max_speed_hz;
    if (hz > kControllerMaxSpeedHz) hz = kControllerMaxSpeedHz;
    return hz;
  };

  {
    transfers.clear();
    off = 0;
    for (const auto& x : xfers) {
      const std::uint32_t hz = speed_of(x);
      const unsigned w = word_bytes(x.bits_per_word ? x.bits_per_word : s.bits_per_word);
      if (!x.tx_buf && !x.rx_buf) {
        // Bufferless: zeros out, MISO dropped; its word delays are time inside the transfer.
        SpiTransfer t;
        t.len = x.len;
        t.speed_hz = hz;
        t.bits_per_word = x.bits_per_word;
        t.delay_usecs = x.delay_usecs;
        t.cs_change = x.cs_change != 0;
        if (x.word_delay_usecs && x.len > w) t.gap_ticks = ((x.len + w - 1) / w - 1) * ticks_from_us(x.word_delay_usecs);
        transfers.push_back(t);
        continue;
      }
      if (x.word_delay_usecs && x.len > w) {
        // One sub-transfer per word, the word delay between them, CS held.
        for (std::size_t k = 0; k < x.len; k += w) {
          const bool last_word = k + w >= x.len;
          SpiTransfer t;
          t.tx = std::span<const std::uint8_t>(wire_tx.data() + off + k, w);
          t.rx = std::span<std::uint8_t>(wire_rx.data() + off + k, w);
          t.len = w;
          t.speed_hz = hz;
          t.bits_per_word = x.bits_per_word;
          t.delay_usecs = last_word ? x.delay_usecs : x.word_delay_usecs;
          t.cs_change = last_word && x.cs_change;
          transfers.push_back(t);
        }
      } else {
        SpiTransfer t;
        t.tx = std::span<const std::uint8_t>(wire_tx.data() + off, x.len);
        t.rx = std::span<std::uint8_t>(wire_rx.data() + off, x.len);
        t.len = x.len;
        t.speed_hz = hz;
        t.bits_per_word = x.bits_per_word;
        t.delay_usecs = x.delay_usecs;
        t.cs_change = x.cs_change != 0;
        transfers.push_back(t);
      }
      off += x.len;
    }
    run_message(dev, transfers, timing);
  }

  off = 0;
  std::size_t rx_off = 0;
  for (const auto& x : xfers) {
    const unsigned w = word_bytes(x.bits_per_word ? x.bits_per_word : s.bits_per_word);
    if (x.rx_buf) {
      from_wire(wire_rx.data() + off, rx.data() + rx_off, x.len, w, lsb_first);
      rx_off += x.len;
    }
    if (x.tx_buf || x.rx_buf) off += x.len;
  }
}

WireSettings spidev_wire_settings(const SpidevSettings& s) {
  WireSettings w;
  w.mode = static_cast<std::uint8_t>(s.mode & (SPI_CPOL | SPI_CPHA));
  w.lsb_first = (s.mode & SPI_LSB_FIRST) != 0;
  w.cs_active_high = (s.mode & SPI_CS_HIGH) != 0;
  w.bits_per_word = s.bits_per_word;
  std::uint32_t hz = s.speed_hz ? s.speed_hz : s.max_speed_hz;
  w.speed_hz = hz > kControllerMaxSpeedHz ? kControllerMaxSpeedHz : hz;
  w.cs_setup_timed = false;  // the controller's own CS-to-clock delay is not known
  return w;
}

}  // namespace l6470emu
