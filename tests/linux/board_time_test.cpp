// The clock rules between a host program and the board, checked deterministically with an
// injected host clock: a message takes its bus time, messages on one bus queue, a polling host
// sees each move last its profile's duration, and edge timestamps are the host's clock at the edge.
#include <gtest/gtest.h>
#include <linux/gpio.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <vector>

#include "linux/device_board.hpp"
#include "spi/message.hpp"
#include "support/test_support.hpp"
#include "support/board_config_support.hpp"

namespace l6470emu::test {
namespace {

/// A host clock that only moves when the test (or a sleep) moves it.
class FakeHostClock final : public HostClock {
 public:
  std::int64_t now = 5'000'000'000;   // CLOCK_MONOTONIC, ns
  std::int64_t realtime_offset = 1'700'000'000'000'000'000;
  bool sleeping_moves_time = true;     // false: a host whose sleeps return at once (to see queueing)
  std::vector<std::int64_t> sleeps;    // every sleep_until deadline

  std::int64_t monotonic_ns() override { return now; }
  std::int64_t realtime_ns() override { return now + realtime_offset; }
  void sleep_until(std::int64_t deadline) override {
    sleeps.push_back(deadline);
    if (sleeping_moves_time && deadline > now) now = deadline;
  }
};

/// A board on a fake clock with one spidev file open per chain.
struct Rig {
  FakeHostClock clock;
  DiagnosticLog log{"off"};
  DeviceBoard board;
  std::vector<NewFile> files;

  explicit Rig(const std::string& text) : board(config_of(text), log, clock) {
    for (std::size_t i = 0; i < board.nodes().size(); ++i)
      if (board.nodes()[i].type == DeviceNode::Type::spidev) files.push_back(board.open(i, true));
  }
  ~Rig() {
    for (const NewFile& f : files) ::close(f.fd);
  }

  /// One message of one-byte transfers with cs_change between them: one CS frame per byte,
  /// as one-chip drivers send commands. Returns the MISO bytes.
  std::vector<std::uint8_t> command(std::size_t chain, std::vector<std::uint8_t> tx, std::uint32_t hz = 5'000'000) {
    std::vector<std::uint8_t> rx(tx.size());
    std::vector<spi_ioc_transfer> x(tx.size());
    for (std::size_t i = 0; i < tx.size(); ++i) {
      x[i].tx_buf = 1;
      x[i].rx_buf = 1;
      x[i].len = 1;
      x[i].speed_hz = hz;
      x[i].cs_change = i + 1 < tx.size();
    }
    EXPECT_EQ(board.spi_message(files[chain].handle, x, tx, rx), static_cast<long>(tx.size()));
    return rx;
  }
  std::uint16_t get_status(std::size_t chain = 0, std::uint32_t hz = 5'000'000) {
    const auto r = command(chain, {0xD0, 0, 0}, hz);
    return static_cast<std::uint16_t>(r[1] << 8 | r[2]);
  }
  std::int32_t abs_pos() {
    const auto r = command(0, {0x21, 0, 0, 0});
    std::int32_t v = r[1] << 16 | r[2] << 8 | r[3];
    return v & 0x200000 ? v - (1 << 22) : v;
  }
  Tick tick() { return board.time().tick_of(clock.now); }
};

/// Bus ticks of one such command of `n` bytes at `hz`: each byte, and the CS-high time after it.
Tick command_ticks(std::size_t n, std::uint32_t hz) {
  return static_cast<Tick>(n) * (transfer_ticks(1, hz) + ticks_from_us(10));
}

TEST(BoardTime, WallTicksAndHostTimeMapBothWaysExactlyAtAnyScale) {
  for (double scale : {1.0, 20.0, 0.5, 3.7}) {
    FakeHostClock clock;
    BoardTime t(TimeConfig{false, scale}, clock);
    EXPECT_EQ(t.now(), 0u);
    for (Tick tick : {Tick{0}, Tick{1}, Tick{7}, Tick{4'000'000}, Tick{123'456'789}}) {
      EXPECT_EQ(t.tick_of(t.host_ns_of(tick)), tick) << "scale " << scale;  // never seen early
      if (tick > 0) {
        EXPECT_LT(t.tick_of(t.host_ns_of(tick) - 1), tick) << "scale " << scale;
      }
    }
    clock.now += 1'000'000'000;  // one host second
    EXPECT_EQ(t.now(), static_cast<Tick>(4'000'000 * scale)) << "scale " << scale;
  }
}

TEST(BoardTime, VirtualTimeMovesOnlyWhenSetAndNeverBackwards) {
  FakeHostClock clock;
  BoardTime t(TimeConfig{true, 1.0}, clock);
  const std::int64_t realtime_at_start = clock.realtime_ns();
  clock.now += 10'000'000'000;  // the host's real clock says nothing to virtual time
  EXPECT_EQ(t.now(), 0u);
  EXPECT_EQ(t.set_now(400), 400u);
  EXPECT_EQ(t.set_now(100), 400u);
  // MONOTONIC starts at the same fixed point every run; REALTIME at the real time of the start.
  EXPECT_EQ(t.host_ns_of(400), kVirtualMonotonicOrigin + 100'000);
  EXPECT_EQ(t.host_ns_of(400) + t.realtime_offset_ns(), realtime_at_start + 100'000);
  t.wait_until(4'000'000);  // nobody else waits: the time simply moves there
  EXPECT_EQ(t.now(), 4'000'000u);
}

TEST(BoardPacing, AMessageReturnsWhenTheHostClockReachesItsLastBit) {
  Rig rig("bus=0 cs=0 chips=L6470");
  const Tick before = rig.tick();
  rig.get_status();
  ASSERT_EQ(rig.clock.sleeps.size(), 1u);
  EXPECT_EQ(rig.tick() - before, command_ticks(3, 5'000'000));
  EXPECT_EQ(rig.clock.now, rig.board.time().host_ns_of(rig.board.now(0)));  // host and chain agree
}

TEST(BoardPacing, EveryBusSpeedFrom10kHzTo5MHzTakesItsOwnBusTime) {
  for (std::uint32_t hz : {10'000u, 100'000u, 1'000'000u, 5'000'000u}) {
    Rig rig("bus=0 cs=0 chips=L6470");
    const Tick before = rig.tick();
    rig.get_status(0, hz);
    EXPECT_EQ(rig.tick() - before, command_ticks(3, hz)) << hz << " Hz";
  }
}

TEST(BoardPacing, AMessageQueuedBehindAnotherOnTheSameBusStartsWhenItEnds) {
  Rig rig("bus=0 cs=0 chips=L6470; bus=0 cs=1 chips=L6470");
  rig.clock.sleeping_moves_time = false;  // both callers are still on the bus at the same host time
  rig.get_status(0);
  rig.get_status(1);
  ASSERT_EQ(rig.clock.sleeps.size(), 2u);
  const BoardTime& t = rig.board.time();
  EXPECT_EQ(t.tick_of(rig.clock.sleeps[0]), command_ticks(3, 5'000'000));
  EXPECT_EQ(t.tick_of(rig.clock.sleeps[1]), 2 * command_ticks(3, 5'000'000));
}

TEST(BoardPacing, MessagesOnDifferentBusesDoNotQueue) {
  Rig rig("bus=0 cs=0 chips=L6470; bus=1 cs=0 chips=L6470");
  rig.clock.sleeping_moves_time = false;
  rig.get_status(0);
  rig.get_status(1);
  ASSERT_EQ(rig.clock.sleeps.size(), 2u);
  EXPECT_EQ(rig.clock.sleeps[0], rig.clock.sleeps[1]);
}

TEST(BoardPacing, AHostPollingWithoutPauseSeesAMoveLastItsProfileDuration) {
  for (std::uint32_t n_step : {200u * 128, 1000u * 128}) {
    Rig rig("bus=0 cs=0 chips=L6470");
    rig.get_status();  // clear UVLO
    const std::int64_t host_start = rig.clock.now;
    rig.command(0, {0x41, static_cast<std::uint8_t>(n_step >> 16), static_cast<std::uint8_t>(n_step >> 8),
                    static_cast<std::uint8_t>(n_step)});
    const Tick decoded = rig.tick() - ticks_from_us(10);  // the Move runs from its last CS rise
    while (!(rig.get_status() & status_bits::kBusyN)) rig.clock.now += 2'000;  // 2 µs of host work per poll
    const Tick seen = rig.tick() - decoded;
    const Tick profile = move_profile_ticks(true, n_step);
    EXPECT_GE(seen, profile) << n_step;
    // STATUS is sampled at the first CS rise of a poll, which returns two frames later: the host
    // learns of the release at most one whole poll (plus its 2 µs of work) after it happened.
    EXPECT_LE(seen, profile + 2 * command_ticks(3, 5'000'000) + ticks_from_us(2)) << n_step;
    EXPECT_GT(rig.clock.now - host_start, 600'000'000);  // 0.631 s / 1.502 s of host time, never 0.065 s
  }
}

TEST(BoardPacing, AHostPollingAt100kHzForOneSecondSeesOneSecondOfRun) {
  Rig rig("bus=0 cs=0 chips=L6470");
  const std::uint32_t spd = spd_from_steps_per_s(200);
  rig.command(0, {0x51, static_cast<std::uint8_t>(spd >> 16), static_cast<std::uint8_t>(spd >> 8),
                  static_cast<std::uint8_t>(spd)});
  const std::int64_t start = rig.clock.now;
  while (rig.clock.now - start < 1'000'000'000) {
    rig.get_status(0, 100'000);
  }
  const Tick at = rig.board.now(0);
  // Whatever the polling, the chain is exactly where the host's clock says it should be.
  EXPECT_EQ(at, rig.tick());
  Chain reference(1);
  ChainHost h(reference, 0);
  reference.advance_to(ticks_from_us(10) + 4 * (transfer_ticks(1, 5'000'000) + ticks_from_us(10)) - ticks_from_us(10));
  h.run(0, true, spd);
  reference.advance_to(at);
  const std::int32_t pos = rig.abs_pos();
  EXPECT_NEAR(pos, reference.chip(0).position(), 2 * 128);  // the reference sends Run a few ticks apart
  EXPECT_GT(pos, 150 * 128);  // about 190 full steps of microsteps, not 4545 full steps
  EXPECT_LT(pos, 200 * 128);
}

TEST(BoardPacing, ScaledTimeRunsTheBoardFasterThanTheHost) {
  Rig rig("bus=0 cs=0 chips=L6470; scale=20");
  const std::int64_t before = rig.clock.now;
  rig.get_status();
  const std::int64_t host_ns = rig.clock.now - before;
  const std::int64_t board_ns = static_cast<std::int64_t>(command_ticks(3, 5'000'000)) * 250;
  EXPECT_GE(host_ns, board_ns / 20);
  EXPECT_LE(host_ns, board_ns / 20 + 1);
}

TEST(BoardPacing, ABusyEdgeCarriesTheHostClockAtTheTickItHappened) {
  for (bool realtime : {false, true}) {
    Rig rig("bus=0 cs=0 chips=L6470");
    const NewFile chip = rig.board.open(1, true);
    ASSERT_GE(chip.result, 0);
    std::vector<std::uint8_t> arg(sizeof(gpio_v2_line_request));
    auto* req = reinterpret_cast<gpio_v2_line_request*>(arg.data());
    req->num_lines = 1;
    req->offsets[0] = 0;  // BUSY of chip 0
    req->config.flags = GPIO_V2_LINE_FLAG_INPUT | GPIO_V2_LINE_FLAG_EDGE_RISING | GPIO_V2_LINE_FLAG_EDGE_FALLING |
                        (realtime ? GPIO_V2_LINE_FLAG_EVENT_CLOCK_REALTIME : 0);
    std::strcpy(req->consumer, "test");
    NewFile line;
    ASSERT_EQ(rig.board.ioctl(chip.handle, GPIO_V2_GET_LINE_IOCTL, arg, &line), 0);

    rig.get_status();
    const std::uint32_t n_step = 3200;
    rig.command(0, {0x40, 0, static_cast<std::uint8_t>(n_step >> 8), static_cast<std::uint8_t>(n_step)});
    const Tick decoded = rig.tick() - ticks_from_us(10);
    rig.clock.now += 2'000'000'000;  // the host sleeps two seconds, then looks
    rig.board.now(0);
    gpio_v2_line_event ev[2]{};
    ASSERT_EQ(recv(line.fd, &ev[0], sizeof ev[0], MSG_DONTWAIT), static_cast<ssize_t>(sizeof ev[0]));
    ASSERT_EQ(recv(line.fd, &ev[1], sizeof ev[1], MSG_DONTWAIT), static_cast<ssize_t>(sizeof ev[1]));
    EXPECT_EQ(ev[0].id, GPIO_V2_LINE_EVENT_FALLING_EDGE);
    EXPECT_EQ(ev[1].id, GPIO_V2_LINE_EVENT_RISING_EDGE);
    const std::int64_t offset = realtime ? rig.clock.realtime_offset : 0;
    const std::int64_t release = rig.board.time().host_ns_of(decoded + move_profile_ticks(false, n_step)) + offset;
    EXPECT_EQ(static_cast<std::int64_t>(ev[1].timestamp_ns), release) << (realtime ? "REALTIME" : "MONOTONIC");
    ::close(line.fd);
    ::close(chip.fd);
  }
}

TEST(BoardBus, ABufferlessTransferOfTwoGigabytesTakesItsBusTimeWithoutTheMemoryOrTheWork) {
  FakeHostClock clock;
  DiagnosticLog log("off");
  DeviceBoard board(config_of("bus=0 cs=0 chips=L6470 mode=3; time=virtual"), log, clock);
  const NewFile f = board.open(0, true);
  spi_ioc_transfer x{};
  x.len = 0x7FFFFFF0;  // the kernel's limit (INT_MAX in total); no tx_buf, no rx_buf: zeros out
  x.speed_hz = 5'000'000;
  EXPECT_EQ(board.spi_message(f.handle, {&x, 1}, {}, {}), 0x7FFFFFF0);
  EXPECT_EQ(board.now(0), Tick{0x7FFFFFF0} * transfer_ticks(1, 5'000'000) + ticks_from_us(10));
  std::vector<std::uint8_t> rx(3);
  std::vector<spi_ioc_transfer> get_status(3);
  const std::uint8_t tx[3] = {0xD0, 0, 0};
  for (int i = 0; i < 3; ++i) {
    get_status[i].tx_buf = get_status[i].rx_buf = 1;
    get_status[i].len = 1;
    get_status[i].cs_change = i < 2;
  }
  ASSERT_EQ(board.spi_message(f.handle, get_status, tx, rx), 3);
  EXPECT_EQ(rx[1] << 8 | rx[2], 0x7C03);  // the zeros were NOPs: power-up STATUS, UVLO latched
  ::close(f.fd);
}

}  // namespace
}  // namespace l6470emu::test
