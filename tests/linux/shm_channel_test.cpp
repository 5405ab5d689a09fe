// The daemon's shared-memory channel (linux/shm_channel.hpp) and its dispatcher
// (serve_shared_request): both sides in one process over one region, a request served from the
// region answers exactly as the same packet on the socket does (bytes, errors, bus time), and
// what the region cannot carry — descriptors, large replies, hostile sizes — is handled.
#include <fcntl.h>
#include <linux/gpio.h>
#include <sys/mman.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <thread>

#include <gtest/gtest.h>

#include "linux/device_board.hpp"
#include "linux/protocol.hpp"
#include "linux/shm_channel.hpp"

namespace l6470emu::test {
namespace {

/// A daemon side and a client side of one fresh region.
struct Pair {
  Pair() {
    int fd = -1;
    daemon = SharedChannel::create(fd);
    if (fd >= 0) {
      client = SharedChannel::attach(fd);
      region_fd = fd;
    }
  }
  ~Pair() {
    if (region_fd >= 0) close(region_fd);
  }
  std::unique_ptr<SharedChannel> daemon, client;
  int region_fd = -1;
};

std::vector<std::uint8_t> packet_of(const RequestHeader& h, std::span<const std::uint8_t> payload = {}) {
  std::vector<std::uint8_t> p(sizeof h + payload.size());
  std::memcpy(p.data(), &h, sizeof h);
  if (!payload.empty()) std::memcpy(p.data() + sizeof h, payload.data(), payload.size());
  return p;
}

/// An SPI_IOC_MESSAGE as the preload sends it: the transfers, then the tx bytes.
std::vector<std::uint8_t> message_packet(std::uint64_t handle, const std::vector<spi_ioc_transfer>& xfers,
                                         const std::vector<std::uint8_t>& tx) {
  std::vector<std::uint8_t> payload(xfers.size() * sizeof(spi_ioc_transfer));
  if (!xfers.empty()) std::memcpy(payload.data(), xfers.data(), payload.size());
  payload.insert(payload.end(), tx.begin(), tx.end());
  const RequestHeader h{static_cast<std::uint32_t>(Op::spi_message), static_cast<std::uint32_t>(payload.size()), handle,
                        xfers.size()};
  return packet_of(h, payload);
}

spi_ioc_transfer xfer(std::uint32_t len, bool tx, bool rx, bool cs_change = false, std::uint32_t speed_hz = 0,
                      std::uint16_t delay_usecs = 0, std::uint8_t bits = 0) {
  spi_ioc_transfer x{};
  x.tx_buf = tx ? 1 : 0;
  x.rx_buf = rx ? 1 : 0;
  x.len = len;
  x.cs_change = cs_change;
  x.speed_hz = speed_hz;
  x.delay_usecs = delay_usecs;
  x.bits_per_word = bits;
  return x;
}

/// A virtual-time board with one L6470 (bufsiz large enough for replies past the region).
struct VirtualBoard {
  VirtualBoard() : board(config(), log), file(board.open(0, true)) {}
  ~VirtualBoard() {
    if (file.fd >= 0) close(file.fd);
  }
  static BoardConfig config() {
    ParseResult p = parse_board_config("bus=0 cs=0 chips=L6470 bufsiz=262144 gpiochip=0; time=virtual", "test");
    return *p.config;
  }
  DiagnosticLog log{"off"};
  DeviceBoard board;
  NewFile file;
};

/// What the client reads back from the region after posting `packet` and the daemon serving it.
struct Served {
  SharedOutcome outcome;
  ReplyHeader reply{};
  std::vector<std::uint8_t> payload;
  int pass_fd = -1;
};

Served serve_through(Pair& pair, DeviceBoard& board, const std::vector<std::uint8_t>& packet) {
  std::memcpy(pair.client->request_area(), packet.data(), packet.size());
  pair.client->post_request(static_cast<std::uint32_t>(packet.size()), 0);
  EXPECT_TRUE(pair.daemon->wait_request(0, {}));
  std::vector<std::uint8_t> scratch(kShmAreaBytes);
  Served s;
  std::vector<std::uint8_t> out;
  s.outcome = serve_shared_request(board, {}, *pair.daemon, scratch.data(), s.reply, out, s.pass_fd);
  if (s.outcome == SharedOutcome::replied) {
    EXPECT_TRUE(pair.client->wait_reply(0, {}));
    const auto r = pair.client->reply();
    EXPECT_GE(r.size(), sizeof(ReplyHeader));
    std::memcpy(&s.reply, r.data(), sizeof s.reply);
    s.payload.assign(r.begin() + sizeof(ReplyHeader), r.end());
  } else {
    s.payload = out;
  }
  return s;
}

TEST(SharedChannel, ARequestPostedByTheClientReachesTheDaemonAndItsReplyComesBack) {
  Pair pair;
  ASSERT_TRUE(pair.daemon && pair.client);
  std::thread daemon([&] {
    std::vector<std::uint8_t> got(kShmAreaBytes);
    for (int i = 0; i < 1000; ++i) {
      ASSERT_TRUE(pair.daemon->wait_request(20'000, {}));
      std::uint32_t flags = 7;
      const std::size_t n = pair.daemon->take_request(got.data(), flags);
      EXPECT_EQ(flags, 0u);
      for (std::size_t k = 0; k < n; ++k) got[k] ^= 0xFF;
      pair.daemon->post_reply({got.data(), n}, {}, 0);
    }
  });
  for (int i = 0; i < 1000; ++i) {
    const std::uint8_t req[3] = {static_cast<std::uint8_t>(i), 2, 3};
    std::memcpy(pair.client->request_area(), req, sizeof req);
    pair.client->post_request(sizeof req, 0);
    ASSERT_TRUE(pair.client->wait_reply(20'000, {}));
    const auto r = pair.client->reply();
    ASSERT_EQ(r.size(), 3u);
    EXPECT_EQ(r[0], static_cast<std::uint8_t>(~i));
    EXPECT_EQ(pair.client->reply_flags(), 0u);
  }
  daemon.join();
}

TEST(SharedChannel, ASleepingDaemonIsWokenByTheNextRequest) {
  // Woken, not found by a periodic look: the reply comes well before the rest of the alive check's
  // period (180 ms after the request, were the wake-up missed). A stall of a loaded machine can
  // make one try slow; a missed wake-up makes every try slow.
  std::chrono::steady_clock::duration took{};
  for (int attempt = 0; attempt < 3; ++attempt) {
    Pair pair;
    ASSERT_TRUE(pair.daemon && pair.client);
    std::thread daemon([&] {
      ASSERT_TRUE(pair.daemon->wait_request(0, {}));  // no spin: straight onto the futex
      std::uint8_t b[8];
      std::uint32_t flags = 0;
      pair.daemon->take_request(b, flags);
      pair.daemon->post_reply({}, {}, kShmOnSocket);
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const auto posted = std::chrono::steady_clock::now();
    pair.client->post_request(0, 0);
    ASSERT_TRUE(pair.client->wait_reply(0, {}));
    took = std::chrono::steady_clock::now() - posted;
    daemon.join();
    EXPECT_EQ(pair.client->reply_flags(), kShmOnSocket);
    if (took < std::chrono::milliseconds(kShmAliveCheckMs / 2)) return;
  }
  ADD_FAILURE() << "three requests took " << std::chrono::duration<double>(took).count() << " s (the last)";
}

TEST(SharedChannel, AWaitEndsWhenThePeerIsGoneInsteadOfSleepingForEver) {
  Pair pair;
  ASSERT_TRUE(pair.daemon && pair.client);
  int asked = 0;
  EXPECT_FALSE(pair.daemon->wait_request(1000, [&] { return ++asked < 2; }));
  EXPECT_EQ(asked, 2);
  pair.client->post_request(0, 0);
  EXPECT_FALSE(pair.client->wait_reply(1000, [] { return false; }));  // no reply, and the daemon is gone
}

TEST(SharedChannel, ASizeBeyondTheAreaIsTakenAsAnEmptyPacket) {
  Pair pair;
  ASSERT_TRUE(pair.daemon && pair.client);
  pair.client->post_request(static_cast<std::uint32_t>(kShmAreaBytes + 1), 0);
  std::vector<std::uint8_t> got(kShmAreaBytes);
  std::uint32_t flags = 0;
  EXPECT_EQ(pair.daemon->take_request(got.data(), flags), 0u);
  pair.client->post_request(0xFFFFFFFF, 0);
  EXPECT_EQ(pair.daemon->take_request(got.data(), flags), 0u);
}

TEST(SharedChannel, TheRegionIsSealedSoAClientCannotShrinkItUnderTheDaemon) {
  Pair pair;
  ASSERT_GE(pair.region_fd, 0);
  EXPECT_NE(ftruncate(pair.region_fd, 0), 0);
  EXPECT_NE(ftruncate(pair.region_fd, static_cast<off_t>(SharedChannel::region_bytes() * 2)), 0);
  EXPECT_EQ(SharedChannel::attach(open("/dev/null", O_RDONLY | O_CLOEXEC)), nullptr);  // not a region
}

TEST(SharedProtocol, MessagesServedFromTheRegionAnswerAsOnTheSocketWithTheSameBusTime) {
  VirtualBoard by_socket, by_region;
  Pair pair;
  ASSERT_TRUE(pair.daemon && pair.client);
  ASSERT_GE(by_socket.file.fd, 0);
  const auto h1 = by_socket.file.handle, h2 = by_region.file.handle;
  struct Case {
    std::vector<spi_ioc_transfer> xfers;
    std::vector<std::uint8_t> tx;
  };
  const std::vector<Case> cases = {
      {{xfer(1, true, true, true), xfer(1, true, true, true), xfer(1, true, true)}, {0xD0, 0, 0}},  // GetStatus
      {{xfer(3, true, false)}, {0x07, 0x00, 0x30}},                                                  // SetParam, CS held
      {{xfer(1, true, false, true, 1'000'000, 50), xfer(2, false, true, false, 200'000)}, {0x27}},   // speeds, a delay
      {{xfer(4097, true, false)}, std::vector<std::uint8_t>(4097)},  // within this bufsiz
      {{xfer(3, true, true, false, 0, 0, 16)}, {1, 2, 3}},          // EINVAL: odd length for 16-bit words
      {{xfer(2, true, true, false, 0, 0, 9)}, {1, 2}},              // EINVAL: no 9-bit words
      {{xfer(300'000, true, false)}, std::vector<std::uint8_t>(300'000)},  // EMSGSIZE: past bufsiz (on the socket)
      {{xfer(1, true, true, true)}, {0x00}},                               // CS held into the next message
      {{xfer(1, true, true)}, {0x00}},
      {{}, {}},  // empty
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto& c = cases[i];
    ReplyHeader expected;
    std::vector<std::uint8_t> expected_payload;
    int fd = -1;
    serve_request(by_socket.board, {}, message_packet(h1, c.xfers, c.tx), expected, expected_payload, fd);
    const auto packet = message_packet(h2, c.xfers, c.tx);
    if (packet.size() > kShmAreaBytes) {  // the preload sends those on the socket
      ReplyHeader r;
      std::vector<std::uint8_t> p;
      serve_request(by_region.board, {}, packet, r, p, fd);
      continue;
    }
    const Served s = serve_through(pair, by_region.board, packet);
    EXPECT_EQ(s.outcome, SharedOutcome::replied) << "case " << i;
    EXPECT_EQ(s.reply.result, expected.result) << "case " << i;
    EXPECT_EQ(s.reply.payload, expected_payload.size()) << "case " << i;
    EXPECT_EQ(s.payload, expected_payload) << "case " << i;
    EXPECT_EQ(by_region.board.now(0), by_socket.board.now(0)) << "case " << i << ": the same bus time";
  }
  EXPECT_GT(by_region.board.now(0), Tick{0});
}

TEST(SharedProtocol, AReplyWithADescriptorOrTooLargeForTheRegionIsLeftForTheSocket) {
  VirtualBoard b;
  Pair pair;
  ASSERT_TRUE(pair.daemon && pair.client);
  // read() of 100 000 bytes: a small request, a reply past the region.
  const RequestHeader read{static_cast<std::uint32_t>(Op::spi_read), 0, b.file.handle, 100'000};
  Served s = serve_through(pair, b.board, packet_of(read));
  EXPECT_EQ(s.outcome, SharedOutcome::reply_on_socket);
  EXPECT_EQ(s.reply.result, 100'000);
  EXPECT_EQ(s.payload.size(), 100'000u);
  EXPECT_EQ(s.reply.payload, 100'000u);
  // A line request: the new file's descriptor can only ride on the socket.
  const NewFile chip = b.board.open(1, true);
  ASSERT_GE(chip.fd, 0);
  gpio_v2_line_request lr{};
  lr.num_lines = 1;
  lr.offsets[0] = 0;
  lr.config.flags = GPIO_V2_LINE_FLAG_INPUT;
  std::strcpy(lr.consumer, "test");
  const RequestHeader ioctl{static_cast<std::uint32_t>(Op::ioctl), sizeof lr, chip.handle, GPIO_V2_GET_LINE_IOCTL};
  s = serve_through(pair, b.board, packet_of(ioctl, {reinterpret_cast<const std::uint8_t*>(&lr), sizeof lr}));
  EXPECT_EQ(s.outcome, SharedOutcome::reply_on_socket);
  EXPECT_EQ(s.reply.result, 0);
  EXPECT_GE(s.pass_fd, 0);
  EXPECT_NE(s.reply.handle, 0u);
  if (s.pass_fd >= 0) close(s.pass_fd);
  close(chip.fd);
}

TEST(SharedProtocol, ARequestMarkedAsSentOnTheSocketIsLeftToTheCaller) {
  VirtualBoard b;
  Pair pair;
  ASSERT_TRUE(pair.daemon && pair.client);
  pair.client->post_request(0, kShmOnSocket);
  ASSERT_TRUE(pair.daemon->wait_request(0, {}));
  std::vector<std::uint8_t> scratch(kShmAreaBytes);
  ReplyHeader reply;
  std::vector<std::uint8_t> out;
  int fd = -1;
  EXPECT_EQ(serve_shared_request(b.board, {}, *pair.daemon, scratch.data(), reply, out, fd),
            SharedOutcome::request_on_socket);
  EXPECT_EQ(b.board.now(0), Tick{0});
}

TEST(SharedProtocol, GarbageInTheRegionIsRefusedAsOnTheSocket) {
  VirtualBoard b;
  Pair pair;
  ASSERT_TRUE(pair.daemon && pair.client);
  // A header announcing more payload than the packet has, an unknown op, a truncated header.
  RequestHeader lying{static_cast<std::uint32_t>(Op::spi_message), 1000, b.file.handle, 1};
  EXPECT_EQ(serve_through(pair, b.board, packet_of(lying)).reply.result, -EPROTO);
  RequestHeader unknown{77, 0, 0, 0};
  EXPECT_EQ(serve_through(pair, b.board, packet_of(unknown)).reply.result, -EPROTO);
  RequestHeader attach{static_cast<std::uint32_t>(Op::attach_shm), 0, 0, 0};  // the connection's business
  EXPECT_EQ(serve_through(pair, b.board, packet_of(attach)).reply.result, -EPROTO);
  pair.client->post_request(static_cast<std::uint32_t>(kShmAreaBytes + 100), 0);
  ASSERT_TRUE(pair.daemon->wait_request(0, {}));
  std::vector<std::uint8_t> scratch(kShmAreaBytes);
  ReplyHeader reply;
  std::vector<std::uint8_t> out;
  int fd = -1;
  EXPECT_EQ(serve_shared_request(b.board, {}, *pair.daemon, scratch.data(), reply, out, fd), SharedOutcome::replied);
  EXPECT_EQ(reply.result, -EPROTO);
}

}  // namespace
}  // namespace l6470emu::test
