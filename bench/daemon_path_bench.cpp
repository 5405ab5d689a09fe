// Where a preload or daemon round trip's time goes (bench/preload_bench.sh measures the whole):
// the board alone running one SPI_IOC_MESSAGE(1) of one byte (DeviceBoard::spi_message, the board's
// share of every round trip, the in-process preload's too), the board serving the same as a
// packet (serve_request), the same through a shared region (serve_shared_request: copy-in,
// dispatch, reply), and the region's hand-off between two threads with a trivial server (the
// cross-core latency a preload client and the daemon pay on top).
// All on a virtual-time board, one L6470 in SPI mode 3 at 5 MHz; no preload library, no second process.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <thread>
#include <vector>

#include <linux/spi/spidev.h>

#include "linux/device_board.hpp"
#include "linux/protocol.hpp"
#include "linux/shm_channel.hpp"

namespace {

using namespace l6470emu;

struct VirtualBoard {
  VirtualBoard() : board(*parse_board_config("bus=0 cs=0 chips=L6470; time=virtual", "bench").config, log),
                   file(board.open(0, true)) {
    // As a driver of these chips sets the bus (and as bench/preload_roundtrips.c does).
    std::uint8_t mode = SPI_MODE_3;
    std::uint32_t hz = 5'000'000;
    board.ioctl(file.handle, SPI_IOC_WR_MODE, {&mode, 1}, nullptr);
    board.ioctl(file.handle, SPI_IOC_WR_MAX_SPEED_HZ, {reinterpret_cast<std::uint8_t*>(&hz), sizeof hz}, nullptr);
  }
  ~VirtualBoard() { close(file.fd); }
  DiagnosticLog log{"off"};
  DeviceBoard board;
  NewFile file;
};

/// The packet the preload sends for one NOP: a header, one transfer, one tx byte.
std::vector<std::uint8_t> nop_packet(std::uint64_t handle) {
  spi_ioc_transfer x{};
  x.tx_buf = 1;
  x.rx_buf = 1;
  x.len = 1;
  const RequestHeader h{static_cast<std::uint32_t>(Op::spi_message), sizeof x + 1, handle, 1};
  std::vector<std::uint8_t> p(sizeof h + sizeof x + 1, 0);
  std::memcpy(p.data(), &h, sizeof h);
  std::memcpy(p.data() + sizeof h, &x, sizeof x);
  return p;
}

/// The board's share of a round trip: one 1-byte message, a NOP or a poll's bytes (0xD0, 0, 0 in
/// turn, one CS frame each), straight into DeviceBoard::spi_message.
void BM_BoardMessage(benchmark::State& state) {
  VirtualBoard b;
  spi_ioc_transfer x{};
  x.tx_buf = 1;
  x.rx_buf = 1;
  x.len = 1;
  std::uint8_t tx = 0, rx = 0;
  const bool poll = state.range(0) != 0;
  std::uint64_t i = 0;
  for (auto _ : state) {
    tx = poll && i++ % 3 == 0 ? 0xD0 : 0x00;
    benchmark::DoNotOptimize(b.board.spi_message(b.file.handle, {&x, 1}, {&tx, 1}, {&rx, 1}));
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(poll ? "getstatus" : "nop");
}
BENCHMARK(BM_BoardMessage)->Arg(0)->Arg(1);

void BM_ServeRequest(benchmark::State& state) {
  VirtualBoard b;
  const auto packet = nop_packet(b.file.handle);
  ReplyHeader reply;
  std::vector<std::uint8_t> out;
  int fd = -1;
  for (auto _ : state) {
    serve_request(b.board, {}, packet, reply, out, fd);
    benchmark::DoNotOptimize(reply.result);
  }
  if (reply.result != 1) state.SkipWithError("the message failed");
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ServeRequest);

void BM_ServeSharedRequest(benchmark::State& state) {
  VirtualBoard b;
  int fd = -1;
  auto daemon = SharedChannel::create(fd);
  auto client = SharedChannel::attach(fd);
  close(fd);
  const auto packet = nop_packet(b.file.handle);
  std::vector<std::uint8_t> scratch(kShmAreaBytes), out;
  ReplyHeader reply;
  int pass_fd = -1;
  for (auto _ : state) {
    std::memcpy(client->request_area(), packet.data(), packet.size());
    client->post_request(static_cast<std::uint32_t>(packet.size()), 0);
    daemon->wait_request(0, {});
    serve_shared_request(b.board, {}, *daemon, scratch.data(), reply, out, pass_fd);
    client->wait_reply(0, {});
    benchmark::DoNotOptimize(client->reply().data());
  }
  if (reply.result != 1) state.SkipWithError("the message failed");
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ServeSharedRequest);

/// Two threads, one region, an echo server: the hand-off alone (spin 20 us, then futex).
void BM_RegionHandOff(benchmark::State& state) {
  int fd = -1;
  auto daemon = SharedChannel::create(fd);
  auto client = SharedChannel::attach(fd);
  close(fd);
  std::atomic<bool> stop{false};
  std::thread server([&] {
    std::vector<std::uint8_t> got(kShmAreaBytes);
    while (daemon->wait_request(kRequestSpinNs, [&] { return !stop.load(); })) {
      std::uint32_t flags = 0;
      const std::size_t n = daemon->take_request(got.data(), flags);
      if (flags == 2) break;
      daemon->post_reply({got.data(), n}, {}, 0);
    }
  });
  const std::uint8_t req[64] = {};
  for (auto _ : state) {
    std::memcpy(client->request_area(), req, sizeof req);
    client->post_request(sizeof req, 0);
    client->wait_reply(kReplySpinNs, {});
  }
  client->post_request(0, 2);
  server.join();
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RegionHandOff)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
