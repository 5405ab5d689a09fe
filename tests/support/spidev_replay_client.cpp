// A tiny spidev client for the umockdev replay test: sends each frame of a list as one
// SPI_IOC_MESSAGE(1) (bits_per_word 0 and no mode ioctls, as umockdev's SPI replay needs)
// and checks the bytes received. Usage: spidev_replay_client DEVICE FRAMES [--ask-mode]
// FRAMES: one frame per line, "TXHEX RXHEX" (RXHEX "-" = do not check). --ask-mode first reads
// the mode, bits per word and speed as most spidev libraries do at open, and prints what each gave.
#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

std::vector<std::uint8_t> from_hex(const std::string& s) {
  std::vector<std::uint8_t> out;
  for (std::size_t i = 0; i + 1 < s.size(); i += 2) out.push_back(static_cast<std::uint8_t>(std::stoul(s.substr(i, 2), nullptr, 16)));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3 && !(argc == 4 && std::strcmp(argv[3], "--ask-mode") == 0)) {
    std::fprintf(stderr, "usage: %s DEVICE FRAMES [--ask-mode]\n", argv[0]);
    return 2;
  }
  const int fd = open(argv[1], O_RDWR);  // open(), not openat(): umockdev's preload wraps open
  if (fd < 0) {
    std::fprintf(stderr, "open %s: %s\n", argv[1], std::strerror(errno));
    return 2;
  }
  if (argc == 4) {
    std::uint8_t mode = 0, bits = 0;
    std::uint32_t speed = 0;
    const int m = ioctl(fd, SPI_IOC_RD_MODE, &mode);
    std::printf("SPI_IOC_RD_MODE: %s\n", m < 0 ? std::strerror(errno) : "ok");
    const int b = ioctl(fd, SPI_IOC_RD_BITS_PER_WORD, &bits);
    std::printf("SPI_IOC_RD_BITS_PER_WORD: %s\n", b < 0 ? std::strerror(errno) : "ok");
    const int h = ioctl(fd, SPI_IOC_RD_MAX_SPEED_HZ, &speed);
    std::printf("SPI_IOC_RD_MAX_SPEED_HZ: %s\n", h < 0 ? std::strerror(errno) : "ok");
  }
  std::ifstream frames(argv[2]);
  std::string line;
  int n = 0;
  while (std::getline(frames, line)) {
    std::istringstream fields(line);
    std::string tx_hex, rx_hex;
    if (!(fields >> tx_hex >> rx_hex)) continue;
    std::vector<std::uint8_t> tx = from_hex(tx_hex), rx(tx.size(), 0xEE);
    spi_ioc_transfer t{};
    t.tx_buf = reinterpret_cast<std::uintptr_t>(tx.data());
    t.rx_buf = reinterpret_cast<std::uintptr_t>(rx.data());
    t.len = static_cast<std::uint32_t>(tx.size());
    if (ioctl(fd, SPI_IOC_MESSAGE(1), &t) < 0) {
      std::fprintf(stderr, "frame %d (%s): SPI_IOC_MESSAGE: %s\n", n + 1, tx_hex.c_str(), std::strerror(errno));
      return 1;
    }
    if (rx_hex != "-" && rx != from_hex(rx_hex)) {
      std::fprintf(stderr, "frame %d (%s): received", n + 1, tx_hex.c_str());
      for (auto b : rx) std::fprintf(stderr, " %02x", b);
      std::fprintf(stderr, ", expected %s\n", rx_hex.c_str());
      return 1;
    }
    ++n;
  }
  close(fd);
  std::printf("%d frames replayed\n", n);
  return 0;
}
