// libFuzzer harness of the daemon's request dispatcher (linux/protocol.hpp serve_request) on
// a virtual-time DeviceBoard: every Op, well-formed and not (truncated headers, payloads longer or
// shorter than announced, oversized counts), spidev and gpio ioctls with argument buffers of
// any size, spi_message with any transfers. About half the packets arrive through a shared
// region (serve_shared_request, linux/shm_channel.hpp) as a hostile client could leave them:
// any size word (past the area too), any flags. Checked: nothing crashes, replies stay bounded,
// a passed descriptor comes only with a handle, a reply the region got fits it. `ctl trace` is
// not run (it writes files).
#include <fuzzer/FuzzedDataProvider.h>
#include <linux/gpio.h>
#include <linux/spi/spidev.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <vector>

#include "fuzz_support.hpp"
#include "linux/device_board.hpp"
#include "linux/log.hpp"
#include "linux/protocol.hpp"
#include "linux/shm_channel.hpp"
#include "linux/serve/control.hpp"

using namespace l6470emu;

namespace {

/// The ioctls the DeviceBoard knows (spidev and gpio uAPI v1/v2), and a few it must refuse.
const std::array<unsigned long, 33> kIoctls = {
    SPI_IOC_RD_MODE,
    SPI_IOC_WR_MODE,
    SPI_IOC_RD_LSB_FIRST,
    SPI_IOC_WR_LSB_FIRST,
    SPI_IOC_RD_BITS_PER_WORD,
    SPI_IOC_WR_BITS_PER_WORD,
    SPI_IOC_RD_MAX_SPEED_HZ,
    SPI_IOC_WR_MAX_SPEED_HZ,
    SPI_IOC_RD_MODE32,
    SPI_IOC_WR_MODE32,
    SPI_IOC_MESSAGE(1),
    GPIO_GET_CHIPINFO_IOCTL,
    GPIO_GET_LINEINFO_IOCTL,
    GPIO_GET_LINEINFO_WATCH_IOCTL,
    GPIO_GET_LINEINFO_UNWATCH_IOCTL,
    GPIO_V2_GET_LINEINFO_IOCTL,
    GPIO_V2_GET_LINEINFO_WATCH_IOCTL,
    GPIO_GET_LINEHANDLE_IOCTL,
    GPIO_GET_LINEEVENT_IOCTL,
    GPIO_V2_GET_LINE_IOCTL,
    GPIOHANDLE_GET_LINE_VALUES_IOCTL,
    GPIOHANDLE_SET_LINE_VALUES_IOCTL,
    GPIOHANDLE_SET_CONFIG_IOCTL,
    GPIO_V2_LINE_GET_VALUES_IOCTL,
    GPIO_V2_LINE_SET_VALUES_IOCTL,
    GPIO_V2_LINE_SET_CONFIG_IOCTL,
    0,
    0x5401,  // TCGETS
    _IOR(SPI_IOC_MAGIC, 9, __u32),
    _IOW(SPI_IOC_MAGIC, 1, __u64),
    _IOWR(0xB4, 0x03, struct gpio_v2_line_info),
    _IOWR(0xB4, 0x0F, struct gpio_v2_line_values),
    _IO(0xB4, 0x0C),
};

class Harness {
 public:
  explicit Harness(FuzzedDataProvider& in) : in_(in) {}

  ~Harness() {
    board_.reset();
    for (int fd : fds_) ::close(fd);
    if (region_fd_ >= 0) ::close(region_fd_);
  }

  void run() {
    BoardConfig config;
    config.time.virtual_time = true;
    config.log = "off";
    const unsigned chains = in_.ConsumeIntegralInRange<unsigned>(1, 3);
    const auto variants = all_variants();
    for (unsigned c = 0; c < chains; ++c) {
      ChainConfig cc;
      cc.bus = in_.ConsumeIntegralInRange<unsigned>(0, 1);
      cc.cs = c;
      cc.path = "/dev/spidev" + std::to_string(cc.bus) + "." + std::to_string(cc.cs);
      const unsigned n = in_.ConsumeIntegralInRange<unsigned>(1, 4);
      for (unsigned k = 0; k < n; ++k)
        cc.chips.push_back(variants[in_.ConsumeIntegralInRange<std::size_t>(0, variants.size() - 1)]);
      if (in_.ConsumeBool()) cc.gpiochip = c;
      cc.max_speed_hz = in_.ConsumeIntegralInRange<std::uint32_t>(1, 10'000'000);
      cc.mode = in_.ConsumeIntegralInRange<std::uint8_t>(0, 3);
      cc.bufsiz = in_.ConsumeIntegralInRange<std::uint32_t>(1, 4096);
      config.chains.push_back(std::move(cc));
    }
    board_ = std::make_unique<DeviceBoard>(config, log_);
    for (int steps = 0; steps < 64 && in_.remaining_bytes() > 0; ++steps) request();
  }

 private:
  std::uint64_t pick_handle() {
    if (!handles_.empty() && !in_.ConsumeBool())
      return handles_[in_.ConsumeIntegralInRange<std::size_t>(0, handles_.size() - 1)];
    return in_.ConsumeIntegralInRange<std::uint64_t>(0, 8);
  }

  /// Fills `p` with bytes of the input (zeros once it runs out).
  void fill(std::uint8_t* p, std::size_t n) {
    if (n == 0) return;
    const std::vector<std::uint8_t> b = in_.ConsumeBytes<std::uint8_t>(n);
    if (!b.empty()) std::memcpy(p, b.data(), b.size());
    std::memset(p + b.size(), 0, n - b.size());
  }

  std::vector<std::uint8_t> spi_message_payload(RequestHeader& h) {
    const std::size_t n = in_.ConsumeIntegralInRange<std::size_t>(0, 6);
    h.arg = in_.ConsumeIntegralInRange<int>(0, 15) == 0 ? in_.ConsumeIntegral<std::uint64_t>() : n;
    std::vector<spi_ioc_transfer> x(n);
    std::size_t tx_bytes = 0;
    for (auto& t : x) {
      if (in_.ConsumeBool()) {
        fill(reinterpret_cast<std::uint8_t*>(&t), sizeof t);  // anything at all
        // A bufferless transfer may announce up to INT_MAX bytes, and the board clocks every one:
        // in a mode other than 3 (the bit-level path, a byte at a time) 2^31 bytes take minutes
        // under the sanitizers. That is work in proportion to the bus time asked for (an hour of
        // a 5 MHz bus), not a hang; one input may ask for at most 1 MiB of it.
        if (!t.tx_buf && !t.rx_buf) t.len = std::min<std::uint32_t>(t.len, 1u << 20);
      } else {
        t.tx_buf = in_.ConsumeBool();
        t.rx_buf = in_.ConsumeBool();
        t.len = in_.ConsumeIntegralInRange<std::uint32_t>(0, 40);
        t.speed_hz = in_.ConsumeBool() ? 0 : in_.ConsumeIntegral<std::uint32_t>();
        t.delay_usecs = in_.ConsumeBool() ? 0 : in_.ConsumeIntegral<std::uint16_t>();
        t.bits_per_word = in_.ConsumeBool() ? 0 : in_.ConsumeIntegral<std::uint8_t>();
        t.cs_change = in_.ConsumeBool();
        t.word_delay_usecs = in_.ConsumeBool() ? 0 : in_.ConsumeIntegral<std::uint8_t>();
      }
      if (t.tx_buf) tx_bytes += t.len;
    }
    std::vector<std::uint8_t> payload(n * sizeof(spi_ioc_transfer));
    if (n) std::memcpy(payload.data(), x.data(), payload.size());
    // The tx data: as announced, or a little more or less.
    std::size_t tx = std::min<std::size_t>(tx_bytes, 1 << 16);
    if (in_.ConsumeIntegralInRange<int>(0, 7) == 0) tx = in_.ConsumeIntegralInRange<std::size_t>(0, 256);
    const std::size_t at = payload.size();
    payload.resize(at + tx);
    fill(payload.data() + at, tx);
    return payload;
  }

  void request() {
    RequestHeader h;
    const int op = in_.ConsumeIntegralInRange<int>(0, 9);
    h.op = op <= 8 ? static_cast<std::uint32_t>(op) : in_.ConsumeIntegral<std::uint32_t>();
    h.handle = pick_handle();
    std::vector<std::uint8_t> payload;
    switch (static_cast<Op>(h.op)) {
      case Op::hello:
        h.arg = in_.ConsumeBool() ? kProtocolVersion : in_.ConsumeIntegral<std::uint64_t>();
        break;
      case Op::open:
        h.arg = in_.ConsumeIntegralInRange<std::uint64_t>(0, 7) | (in_.ConsumeBool() ? kOpenCloexec : 0);
        break;
      case Op::closed:
        // The host closes its descriptor first (or not: then the handle must stay).
        if (in_.ConsumeBool() && !fds_.empty()) {
          const std::size_t i = in_.ConsumeIntegralInRange<std::size_t>(0, fds_.size() - 1);
          ::close(fds_[i]);
          fds_.erase(fds_.begin() + static_cast<std::ptrdiff_t>(i));
        }
        break;
      case Op::ioctl: {
        const unsigned long cmd = in_.ConsumeIntegralInRange<int>(0, 7) == 0
                                      ? in_.ConsumeIntegral<std::uint32_t>()
                                      : kIoctls[in_.ConsumeIntegralInRange<std::size_t>(0, kIoctls.size() - 1)];
        h.arg = cmd;
        std::size_t size = _IOC_SIZE(cmd);
        if (in_.ConsumeIntegralInRange<int>(0, 5) == 0) size = in_.ConsumeIntegralInRange<std::size_t>(0, 1200);
        payload.resize(size);
        fill(payload.data(), size);
        break;
      }
      case Op::spi_message:
        payload = spi_message_payload(h);
        break;
      case Op::spi_read:
        h.arg = in_.ConsumeBool() ? in_.ConsumeIntegralInRange<std::uint64_t>(0, 64) : in_.ConsumeIntegral<std::uint64_t>();
        break;
      case Op::spi_write:
        payload = in_.ConsumeBytes<std::uint8_t>(in_.ConsumeIntegralInRange<std::size_t>(0, 64));
        break;
      case Op::control: {
        std::string text = in_.ConsumeRandomLengthString(80);
        static constexpr const char* kCommands[] = {"status", "get ABS_POS --chip 0", "dump", "chains",
                                                    "sw closed --chip 0", "pin STBY_RST 0 --chip 0",
                                                    "fault thermal warning --chip 0", "adc 7 --chip 0", "time",
                                                    "advance 1.5", "help"};
        if (in_.ConsumeBool()) text = kCommands[in_.ConsumeIntegralInRange<std::size_t>(0, std::size(kCommands) - 1)];
        payload.assign(text.begin(), text.end());
        break;
      }
      default:
        payload = in_.ConsumeBytes<std::uint8_t>(in_.ConsumeIntegralInRange<std::size_t>(0, 32));
        break;
    }
    h.payload = static_cast<std::uint32_t>(payload.size());
    // Malformed frames: a payload size that lies, or a packet cut inside the header.
    std::size_t cut = sizeof h + payload.size();
    switch (in_.ConsumeIntegralInRange<int>(0, 15)) {
      case 0: h.payload = in_.ConsumeIntegral<std::uint32_t>(); break;
      case 1: cut = in_.ConsumeIntegralInRange<std::size_t>(0, cut); break;
      default: break;
    }
    std::vector<std::uint8_t> packet(sizeof h + payload.size());
    std::memcpy(packet.data(), &h, sizeof h);
    if (!payload.empty()) std::memcpy(packet.data() + sizeof h, payload.data(), payload.size());
    packet.resize(cut);

    ReplyHeader reply;
    std::vector<std::uint8_t> out;
    int pass_fd = -1;
    if (in_.ConsumeBool() && through_region(packet, reply, out, pass_fd)) {
      // served from the shared region (checked there)
    } else {
      serve_request(*board_, control_, packet, reply, out, pass_fd);
    }
    FUZZ_CHECK(out.size() <= kMaxMessage + 65536, "reply payload of %zu bytes", out.size());
    if (pass_fd >= 0) {
      FUZZ_CHECK(reply.result >= 0 && reply.handle != 0, "a descriptor passed with result %lld, handle %llu",
                 static_cast<long long>(reply.result), static_cast<unsigned long long>(reply.handle));
      fds_.push_back(pass_fd);
      handles_.push_back(reply.handle);
      // Keep the descriptor count bounded: the oldest host ends are closed.
      if (fds_.size() > 24) {
        ::close(fds_.front());
        fds_.erase(fds_.begin());
      }
    }
  }

  /// Posts `packet` in the shared region as a client would (or with a size word and flags that
  /// lie) and serves it. False when the packet is for the socket (too large for the region, or
  /// the region could not be made), which the caller then serves as the socket's.
  bool through_region(const std::vector<std::uint8_t>& packet, ReplyHeader& reply, std::vector<std::uint8_t>& out,
                      int& pass_fd) {
    if (packet.size() > kShmAreaBytes) return false;
    if (!daemon_side_) {
      daemon_side_ = SharedChannel::create(region_fd_);
      if (!daemon_side_) return false;
      client_side_ = SharedChannel::attach(region_fd_);
      if (!client_side_) return false;
      scratch_.resize(kShmAreaBytes);
    }
    if (!packet.empty()) std::memcpy(client_side_->request_area(), packet.data(), packet.size());
    std::uint32_t size = static_cast<std::uint32_t>(packet.size());
    std::uint32_t flags = 0;
    switch (in_.ConsumeIntegralInRange<int>(0, 15)) {
      case 0: size = in_.ConsumeIntegral<std::uint32_t>(); break;
      case 1: size = static_cast<std::uint32_t>(kShmAreaBytes) + in_.ConsumeIntegralInRange<std::uint32_t>(0, 4096); break;
      case 2: flags = in_.ConsumeIntegral<std::uint32_t>(); break;
      default: break;
    }
    client_side_->post_request(size, flags);
    FUZZ_CHECK(daemon_side_->wait_request(0, {}), "a posted request was not seen");
    const SharedOutcome done = serve_shared_request(*board_, control_, *daemon_side_, scratch_.data(), reply, out, pass_fd);
    if (done == SharedOutcome::request_on_socket) {
      FUZZ_CHECK(flags & kShmOnSocket, "a request taken for the socket's without the flag");
      return false;
    }
    if (done == SharedOutcome::replied) {
      FUZZ_CHECK(pass_fd < 0, "a descriptor left behind by a reply in the region");
      FUZZ_CHECK(client_side_->wait_reply(0, {}), "a reply in the region was not seen");
      const auto r = client_side_->reply();
      FUZZ_CHECK(r.size() == sizeof(ReplyHeader) + out.size() && r.size() <= kShmAreaBytes,
                 "region reply of %zu bytes for a payload of %zu", r.size(), out.size());
    } else {
      FUZZ_CHECK(pass_fd >= 0 || sizeof(ReplyHeader) + out.size() > kShmAreaBytes,
                 "a reply that fits the region was sent to the socket");
    }
    return true;
  }

  FuzzedDataProvider& in_;
  int region_fd_ = -1;
  std::unique_ptr<SharedChannel> daemon_side_, client_side_;
  std::vector<std::uint8_t> scratch_;
  DiagnosticLog log_{"off"};
  std::unique_ptr<DeviceBoard> board_;
  std::vector<int> fds_;
  std::vector<std::uint64_t> handles_;
  ControlHandler control_ = [this](const std::string& command, std::string& output) {
    // `trace start FILE` would write files wherever the input says.
    if (command.find("trace") != std::string::npos) return 1;
    return run_control(*board_, command, output);
  };
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::count_input(size);
  FuzzedDataProvider in(data, size);
  Harness h(in);
  h.run();
  return 0;
}
