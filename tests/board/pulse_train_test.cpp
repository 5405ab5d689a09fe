// Pulse trains on the board (board_pulses.cpp): the closed-form edge times, a train on an
// L6474's STCK moving ABS_POS by exactly its pulses in bulk, stopped mid-train, a pulse high
// when looked at, the edges one by one on a recorded chain, whose trace replays exactly.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "board/board.hpp"
#include "daisychain/host.hpp"
#include "daisychain/replay.hpp"
#include "spi/trace_native.hpp"
#include "support/test_support.hpp"

namespace l6470emu::test {
namespace {

class StillHostClock final : public HostClock {
 public:
  std::int64_t monotonic_ns() override { return 0; }
  std::int64_t realtime_ns() override { return 0; }
  void sleep_until(std::int64_t) override {}
};

struct VirtualBoard {
  explicit VirtualBoard(const std::string& description)
      : board(*parse_board_config(description, "test").config, [this](std::string_view l) { log.emplace_back(l); }, clock) {}
  StillHostClock clock;
  std::vector<std::string> log;
  Board board;
  /// Enables the L6474s (HardStop's opcode) through a transfer, DIR high (forward).
  void enable(std::size_t chip_count = 1) {
    for (std::size_t k = 0; k < chip_count; ++k) board.drive_pin(0, k, Pin::DIR, true);
    std::vector<std::uint8_t> tx(chip_count, 0xB8), rx(chip_count);
    SpiTransfer t;
    t.tx = tx;
    t.rx = rx;
    t.len = static_cast<std::uint32_t>(chip_count);
    board.advance_to(board.transfer(0, std::span<const SpiTransfer>(&t, 1)));
  }
  std::int32_t position(std::size_t chip = 0) {
    std::int32_t p = 0;
    board.with_chain(0, [&](Chain& c) { p = c.chip(chip).position(); });
    return p;
  }
};

PulseTrain train_of(Tick start, std::uint64_t clock_hz, std::uint64_t period, std::uint64_t high, std::uint64_t count = 0) {
  PulseTrain t;
  t.start = start;
  t.clock_hz = clock_hz;
  t.period_counts = period;
  t.high_counts = high;
  t.count = count;
  return t;
}

TEST(PulseTrain, EdgeCountsAgreeWithTheEdgeTicksOneByOne) {
  const PulseTrain trains[] = {train_of(100, 4'000'000, 7, 3), train_of(0, 84'000'000, 84'000, 42'000),
                               train_of(5, 3'000'000, 10, 1, 40), train_of(0, 2 * 440, 2, 1)};
  for (const PulseTrain& t : trains)
    for (std::uint64_t k = 0; k < 30; ++k) {
      EXPECT_EQ(t.rises_through(t.rise_tick(k)), k + 1);
      EXPECT_EQ(t.rises_through(t.rise_tick(k) - 1), t.rise_tick(k) > t.start ? k : 0);
      EXPECT_EQ(t.falls_through(t.fall_tick(k)), k + 1);
      EXPECT_EQ(t.falls_through(t.fall_tick(k) - 1), k);
    }
  EXPECT_EQ(train_of(0, 84'000'000, 84'000, 42'000).rise_tick(1), 4000u) << "1 kHz from 84 MHz: 4000 ticks";
  EXPECT_EQ(train_of(5, 3'000'000, 10, 1, 40).rises_through(kNever / 2), 40u) << "a count is a count";
}

TEST(PulseTrainOnTheBoard, OneKilohertzForTenMinutesMovesAbsPosByExactlyItsPulsesInBulk) {
  VirtualBoard v("chips=L6474; time=virtual");
  v.enable();
  ASSERT_TRUE(v.board.drive_pulse_train(0, 0, Pin::STCK, train_of(v.board.time().now(), 84'000'000, 84'000, 42'000)));
  v.board.advance_to(v.board.time().now() + ticks_from_ms(600'000) - 1);  // the last pulse rises at 599.999 s
  EXPECT_EQ(v.position(), 600'000);
  EXPECT_EQ(v.board.pulse_train_rises(0, 0, Pin::STCK), 600'000u);
  EXPECT_EQ(v.board.pulse_train_counts().single_edges, 0u) << "not simulated pulse by pulse";
  EXPECT_EQ(v.board.pulse_train_counts().bulk_pulses, 600'000u);
}

TEST(PulseTrainOnTheBoard, AStoppedTrainMovesNoMoreAndACountedTrainEndsByItself) {
  VirtualBoard v("chips=2xL6474; time=virtual");
  v.enable(2);
  const Tick t0 = v.board.time().now();
  ASSERT_TRUE(v.board.drive_pulse_train(0, 0, Pin::STCK, train_of(t0, kTicksPerSecond, 400, 200)));
  ASSERT_TRUE(v.board.drive_pulse_train(0, 1, Pin::STCK, train_of(t0, kTicksPerSecond, 400, 200, 25)));
  v.board.advance_to(t0 + 400 * 10 + 100);  // pulse 10 high
  EXPECT_EQ(v.position(0), 11) << "the pulse high at the look has stepped";
  ASSERT_TRUE(v.board.stop_pulse_train(0, 0, Pin::STCK));
  EXPECT_FALSE(v.board.pin_level(0, 0, Pin::STCK));
  v.board.advance_to(t0 + 400 * 1000);
  EXPECT_EQ(v.position(0), 11);
  EXPECT_EQ(v.position(1), 25);
  EXPECT_EQ(v.board.pulse_train_rises(0, 1, Pin::STCK), 25u);
  EXPECT_FALSE(v.board.stop_pulse_train(0, 1, Pin::STCK)) << "it ended by itself";
}

TEST(PulseTrainOnTheBoard, ATrainReplacedAtOneOfItsRisingEdgesMakesThatPulseOnce) {
  VirtualBoard v("chips=L6474; time=virtual");
  v.enable();
  const Tick t0 = v.board.time().now();
  ASSERT_TRUE(v.board.drive_pulse_train(0, 0, Pin::STCK, train_of(t0, kTicksPerSecond, 100, 50)));
  v.board.advance_to(t0 + 300);  // pulses at 0, 100, 200, 300: the last one high
  ASSERT_TRUE(v.board.drive_pulse_train(0, 0, Pin::STCK, train_of(t0 + 300, kTicksPerSecond, 40, 20)));
  v.board.advance_to(t0 + 300 + 40 * 9 + 5);  // the new train's pulses at 300, 340, ..., 660
  EXPECT_EQ(v.position(), 3 + 10);
  EXPECT_EQ(v.board.pulse_train_rises(0, 0, Pin::STCK), 13u);
  EXPECT_EQ(v.board.pulse_train_counts().bulk_pulses, 13u);
}

TEST(PulseTrainOnTheBoard, ABadTrainIsRefused) {
  VirtualBoard v("chips=L6474; time=virtual");
  EXPECT_FALSE(v.board.drive_pulse_train(0, 0, Pin::STCK, train_of(0, kTicksPerSecond, 4, 4)));
  EXPECT_FALSE(v.board.drive_pulse_train(0, 0, Pin::BUSY, train_of(0, kTicksPerSecond, 4, 2)));
  EXPECT_FALSE(v.board.drive_pulse_train(0, 3, Pin::STCK, train_of(0, kTicksPerSecond, 4, 2)));
  v.board.advance_to(100);
  EXPECT_FALSE(v.board.drive_pulse_train(0, 0, Pin::STCK, train_of(50, kTicksPerSecond, 4, 2))) << "in the past";
}

TEST(PulseTrainOnTheBoard, ARecordedTrainRecordsEveryEdgeAndReplaysToTheSamePosition) {
  VirtualBoard v("chips=L6474; time=virtual");
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("l6470emu-train-" + std::to_string(std::random_device{}()) + ".trace")).string();
  ASSERT_EQ(v.board.start_recording(0, path), "");
  v.enable();
  ASSERT_TRUE(v.board.drive_pulse_train(0, 0, Pin::STCK, train_of(v.board.time().now(), kTicksPerSecond, 40, 10, 300)));
  v.board.advance(ticks_from_ms(5));
  EXPECT_EQ(v.position(), 300);
  EXPECT_EQ(v.board.pulse_train_counts().single_edges, 600u) << "recorded: edge by edge";
  ASSERT_TRUE(v.board.stop_recording(0));
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  std::remove(path.c_str());
  const std::string recorded = text.str();
  NativeTraceReader reader(recorded, "train.trace");
  Chain fresh(1, l6474());
  const ReplayResult r = replay_trace(reader, fresh);
  EXPECT_TRUE(r.matched()) << (r.divergences.empty() ? "" : r.divergences[0].report);
  EXPECT_EQ(fresh.chip(0).position(), 300);
}

}  // namespace
}  // namespace l6470emu::test
