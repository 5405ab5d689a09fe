// spidev settings, message validation and wire order, as drivers/spi/spidev.c and spi.c do them.
#include "linux/spidev_rules.hpp"

#include <asm/ioctl.h>
#include <cerrno>
#include <algorithm>
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
    // spidev: a transfer without speed_hz gets the file's speed; __spi_validate: still none, the
    // device's; faster than the controller is clamped, slower than it can go is refused.
    std::uint32_t hz = x.speed_hz ? x.speed_hz : s.speed_hz ? s.speed_hz : s.max_speed_hz;
    if (hz > kControllerMaxSpeedHz) hz = kControllerMaxSpeedHz;
    if (hz != 0 && hz < kControllerMinSpeedHz) return -EINVAL;
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

void SpidevWireMessage::prepare(const SpidevSettings& s, std::span<const spi_ioc_transfer> xfers,
                                std::span<const std::uint8_t> tx) {
  // Wire buffers for the transfers that have a buffer; bufferless ones (zeros out, nothing in)
  // need none, however long they are.
  std::size_t total = 0;
  for (const auto& x : xfers)
    if (x.tx_buf || x.rx_buf) total += x.len;
  wire_tx_.assign(total, 0);
  wire_rx_.assign(total, 0);
  settings_ = s;
  xfers_ = xfers;
  const bool lsb_first = (s.mode & SPI_LSB_FIRST) != 0;

  std::size_t off = 0, tx_off = 0;
  for (const auto& x : xfers) {
    const unsigned w = word_bytes(x.bits_per_word ? x.bits_per_word : s.bits_per_word);
    if (x.tx_buf) {
      to_wire(tx.data() + tx_off, wire_tx_.data() + off, x.len, w, lsb_first);
      tx_off += x.len;
    }
    if (x.tx_buf || x.rx_buf) off += x.len;
  }

  timing_ = {};
  timing_.default_speed_hz = s.speed_hz ? s.speed_hz : s.max_speed_hz;
  timing_.cs_high_ticks = ticks_from_us(10);  // spi.c's default cs_change delay
  timing_.wire = spidev_wire_settings(s);
  auto speed_of = [&](const spi_ioc_transfer& x) {
    std::uint32_t hz = x.speed_hz ? x.speed_hz : s.speed_hz;
    if (hz == 0) hz = s.max_speed_hz;
    if (hz > kControllerMaxSpeedHz) hz = kControllerMaxSpeedHz;
    return hz;
  };

  transfers_.clear();
  next_ = 0;
  done_in_next_ = 0;
  cs_high_left_ = 0;
  bus_ticks_ = 0;
  cs_high_mode_ = false;  // an active-high CS is the wire's to model (ChainBus): it selects no chip
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
      transfers_.push_back(t);
      continue;
    }
    if (x.word_delay_usecs && x.len > w) {
      // One sub-transfer per word, the word delay between them, CS held.
      for (std::size_t k = 0; k < x.len; k += w) {
        const bool last_word = k + w >= x.len;
        SpiTransfer t;
        t.tx = std::span<const std::uint8_t>(wire_tx_.data() + off + k, w);
        t.rx = std::span<std::uint8_t>(wire_rx_.data() + off + k, w);
        t.len = w;
        t.speed_hz = hz;
        t.bits_per_word = x.bits_per_word;
        t.delay_usecs = last_word ? x.delay_usecs : x.word_delay_usecs;
        t.cs_change = last_word && x.cs_change;
        transfers_.push_back(t);
      }
    } else {
      SpiTransfer t;
      t.tx = std::span<const std::uint8_t>(wire_tx_.data() + off, x.len);
      t.rx = std::span<std::uint8_t>(wire_rx_.data() + off, x.len);
      t.len = x.len;
      t.speed_hz = hz;
      t.bits_per_word = x.bits_per_word;
      t.delay_usecs = x.delay_usecs;
      t.cs_change = x.cs_change != 0;
      transfers_.push_back(t);
    }
    off += x.len;
  }
}

Tick SpidevWireMessage::bus_ticks() const {
  if (cs_high_mode_) return bus_ticks_;
  Tick total = 0;
  for (std::size_t i = 0; i < transfers_.size(); ++i) {
    const SpiTransfer& t = transfers_[i];
    total += Tick{t.len} * transfer_ticks(1, t.speed_hz ? t.speed_hz : timing_.default_speed_hz) + t.gap_ticks +
             ticks_from_us(t.delay_usecs) + (raises_after(i) ? timing_.cs_high_ticks : 0);
  }
  return total;
}

bool SpidevWireMessage::raises_after(std::size_t i) const {
  // run_message: after a transfer other than the last, cs_change raises CS; after the last, it keeps CS low.
  const bool last = i + 1 == transfers_.size();
  return last ? !transfers_[i].cs_change : transfers_[i].cs_change;
}

bool SpidevWireMessage::run(SpiDevice& dev, Tick budget) {
  if (cs_high_mode_) {
    const Tick step = std::min(budget, cs_high_left_);
    dev.advance_to(dev.now() + step);
    cs_high_left_ -= step;
    return cs_high_left_ == 0;
  }
  if (budget == kNever && next_ == 0 && done_in_next_ == 0) {
    run_message(dev, transfers_, timing_);  // the whole message at once (the usual case)
    next_ = transfers_.size();
    return true;
  }
  // A piece: whole transfers and parts of one, as much as fits the budget (at least one byte).
  // Each keeps CS as the whole message would: run_message raises CS after the last transfer of
  // a call unless its cs_change says otherwise, so the piece's last one is given the cs_change
  // that makes run_message do what it would have done there in the whole message.
  piece_.clear();
  Tick used = 0;
  bool last_raises = false;
  while (next_ < transfers_.size() && (used < budget || piece_.empty())) {
    const SpiTransfer& t = transfers_[next_];
    const Tick per_byte = transfer_ticks(1, t.speed_hz ? t.speed_hz : timing_.default_speed_hz);
    std::uint32_t take = t.len - done_in_next_;
    if (budget != kNever) {
      const Tick room = used < budget ? budget - used : 0;
      take = static_cast<std::uint32_t>(std::min<Tick>(take, std::max<Tick>(1, room / per_byte)));
      // Bufferless transfers are clocked in blocks of 4096 (message.cpp): cut only between blocks.
      if (t.tx.empty() && t.rx.empty() && take < t.len - done_in_next_)
        take = std::min<std::uint32_t>(t.len - done_in_next_, (take + 4095) / 4096 * 4096);
    }
    SpiTransfer part = t;
    part.len = take;
    if (!t.tx.empty()) part.tx = t.tx.subspan(done_in_next_, take);
    if (!t.rx.empty()) part.rx = t.rx.subspan(done_in_next_, take);
    const bool finishes = done_in_next_ + take == t.len;
    if (!finishes) {
      part.delay_usecs = 0;
      part.gap_ticks = 0;
    }
    last_raises = finishes && raises_after(next_);
    part.cs_change = last_raises;  // as a transfer in the middle of a call: raise when it would
    piece_.push_back(part);
    used += Tick{take} * per_byte +
            (finishes ? t.gap_ticks + ticks_from_us(t.delay_usecs) + (last_raises ? timing_.cs_high_ticks : 0) : 0);
    if (finishes) {
      ++next_;
      done_in_next_ = 0;
    } else {
      done_in_next_ += take;
    }
  }
  if (!piece_.empty()) {
    piece_.back().cs_change = !last_raises;  // the last of the call: cs_change keeps CS low
    run_message(dev, piece_, timing_);
  }
  return next_ == transfers_.size();
}

void SpidevWireMessage::abandon(SpiDevice& dev) {
  if (!cs_high_mode_ && dev.selected()) dev.deselect();
  next_ = transfers_.size();
  cs_high_left_ = 0;
}

void SpidevWireMessage::finish(std::span<std::uint8_t> rx) const {
  const bool lsb_first = (settings_.mode & SPI_LSB_FIRST) != 0;
  std::size_t off = 0, rx_off = 0;
  for (const auto& x : xfers_) {
    const unsigned w = word_bytes(x.bits_per_word ? x.bits_per_word : settings_.bits_per_word);
    if (x.rx_buf) {
      from_wire(wire_rx_.data() + off, rx.data() + rx_off, x.len, w, lsb_first);
      rx_off += x.len;
    }
    if (x.tx_buf || x.rx_buf) off += x.len;
  }
}

void run_spidev_message(SpiDevice& dev, const SpidevSettings& s, std::span<const spi_ioc_transfer> xfers,
                        std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  thread_local SpidevWireMessage message;  // its buffers keep their capacity from one message to the next
  message.prepare(s, xfers, tx);
  message.run(dev, kNever);
  message.finish(rx);
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
