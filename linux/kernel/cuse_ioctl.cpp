#include "linux/kernel/cuse_ioctl.hpp"

#include <linux/spi/spidev.h>

#include <cerrno>
#include <cstring>

namespace l6470emu {

namespace {

CuseIoctlStep done(long result, std::vector<std::uint8_t> data = {}) {
  CuseIoctlStep s;
  s.result = result;
  s.data = std::move(data);
  return s;
}

CuseIoctlStep retry(std::vector<CuseRange> in, std::vector<CuseRange> out) {
  CuseIoctlStep s;
  s.retry = true;
  s.in = std::move(in);
  s.out = std::move(out);
  return s;
}

CuseIoctlStep message(DeviceBoard& board, std::uint64_t handle, std::uint32_t bufsiz, std::size_t n, std::uint64_t arg,
                      std::span<const std::uint8_t> in, std::size_t out_size, const CuseLimits& limits) {
  if (n == 0) return done(0);  // spidev answers SPI_IOC_MESSAGE(0) without reading anything
  const std::size_t array = n * sizeof(spi_ioc_transfer);
  if (in.size() < array) {
    if (array > limits.max_bytes) return done(-ENOMEM);
    return retry({{arg, array}}, {});
  }
  std::vector<spi_ioc_transfer> xfers(n);
  std::memcpy(xfers.data(), in.data(), array);
  // spidev_message's first loop checks the sizes before it copies any tx data.
  if (const long sizes = spidev_message_sizes(bufsiz, xfers); sizes < 0) return done(sizes);
  const std::size_t tx_bytes = spidev_tx_bytes(xfers), rx_bytes = spidev_rx_bytes(xfers);
  // Everything is in once the array and the tx data came and the rx buffers are named (a
  // message without data is complete with the array alone).
  if (in.size() == array + tx_bytes && out_size == rx_bytes) {
    std::vector<std::uint8_t> rx(rx_bytes);
    const long r = board.spi_message(handle, xfers, in.subspan(array, tx_bytes), rx);
    if (r < 0) return done(r);
    return done(r, std::move(rx));
  }
  std::vector<CuseRange> tx_ranges{{arg, array}}, rx_ranges;
  for (const auto& x : xfers) {
    if (x.tx_buf && x.len) tx_ranges.push_back({x.tx_buf, x.len});
    if (x.rx_buf && x.len) rx_ranges.push_back({x.rx_buf, x.len});
  }
  if (tx_ranges.size() + rx_ranges.size() > limits.max_ranges || array + tx_bytes > limits.max_bytes ||
      rx_bytes > limits.max_bytes)
    return done(-ENOMEM);
  return retry(std::move(tx_ranges), std::move(rx_ranges));
}

}  // namespace

CuseIoctlStep spidev_cuse_ioctl(DeviceBoard& board, std::uint64_t handle, std::uint32_t bufsiz, unsigned long cmd,
                                std::uint64_t arg, std::span<const std::uint8_t> in, std::size_t out_size,
                                const CuseLimits& limits) {
  if (_IOC_TYPE(cmd) != SPI_IOC_MAGIC) return done(-ENOTTY);
  std::size_t n = 0;
  if (is_spi_message_ioctl(cmd, n)) {
    if (_IOC_SIZE(cmd) % sizeof(spi_ioc_transfer)) return done(-EINVAL);
    return message(board, handle, bufsiz, n, arg, in, out_size, limits);
  }
  // A settings ioctl: its argument is copied in (writes) or out (reads) whole.
  if (!is_spidev_settings_ioctl(cmd)) return done(-ENOTTY);
  const std::size_t size = _IOC_SIZE(cmd);
  const unsigned dir = _IOC_DIR(cmd);
  const bool need_in = dir & _IOC_WRITE, need_out = dir & _IOC_READ;
  if ((need_in && in.size() < size) || (need_out && out_size < size)) {
    std::vector<CuseRange> r_in, r_out;
    if (need_in) r_in.push_back({arg, size});
    if (need_out) r_out.push_back({arg, size});
    return retry(std::move(r_in), std::move(r_out));
  }
  std::vector<std::uint8_t> value(size);
  if (need_in) std::memcpy(value.data(), in.data(), size);
  const long r = board.ioctl(handle, cmd, value, nullptr);
  if (r < 0) return done(r);
  if (!need_out) value.clear();
  return done(r, std::move(value));
}

}  // namespace l6470emu
