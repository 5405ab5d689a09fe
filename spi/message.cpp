// spidev message execution: Linux spi_sync semantics of cs_change and delay_usecs.
#include "spi/message.hpp"

#include <algorithm>

namespace l6470emu {

Tick transfer_ticks(std::uint32_t bytes, std::uint32_t speed_hz) {
  if (bytes == 0) return 0;
  if (speed_hz == 0) speed_hz = 1;
  const std::uint64_t bits = std::uint64_t{bytes} * 8;
  const Tick t = (bits * kTicksPerSecond + speed_hz - 1) / speed_hz;
  return std::max<Tick>(t, bytes);
}

void run_message(SpiDevice& dev, std::span<const SpiTransfer> transfers, const BusTiming& timing) {
  WireSettings wire = timing.wire;
  for (std::size_t i = 0; i < transfers.size(); ++i) {
    const SpiTransfer& t = transfers[i];
    const bool last = i + 1 == transfers.size();
    if (!dev.selected()) dev.select_wire();
    const std::uint32_t speed = t.speed_hz ? t.speed_hz : timing.default_speed_hz;
    wire.speed_hz = speed;
    wire.bits_per_word = t.bits_per_word ? t.bits_per_word : timing.wire.bits_per_word;
    const Tick per_byte = transfer_ticks(1, speed);
    // A block of bytes at a time (a whole transfer, up to 4096 bytes): the bytes carry no time
    // of their own inside a frame (the chips decode at the CS rising edge), so the block's time
    // passes first. Without a tx buffer zeros go out; without an rx buffer MISO is dropped (the
    // kernel allows up to INT_MAX bytes of a bufferless transfer).
    static constexpr std::uint8_t kZeros[4096] = {};
    std::uint8_t sink[sizeof kZeros];
    for (std::uint32_t k = 0; k < t.len;) {
      const std::uint32_t block = std::min<std::uint32_t>(t.len - k, sizeof kZeros);
      dev.advance_to(dev.now() + per_byte * block);
      dev.exchange_wire(t.tx.empty() ? std::span<const std::uint8_t>(kZeros, block) : t.tx.subspan(k, block),
                        t.rx.empty() ? std::span<std::uint8_t>(sink, block) : t.rx.subspan(k, block), wire);
      k += block;
    }
    if (t.gap_ticks) dev.advance_to(dev.now() + t.gap_ticks);
    if (t.delay_usecs) dev.advance_to(dev.now() + ticks_from_us(t.delay_usecs));
    const bool raise = last ? !t.cs_change : t.cs_change;
    if (raise) {
      dev.deselect_wire();
      dev.advance_to(dev.now() + timing.cs_high_ticks);
    }
  }
}

}  // namespace l6470emu
