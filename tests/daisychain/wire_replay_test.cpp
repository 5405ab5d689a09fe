// A recording carries how its host drove the wire (TraceEvent::wire, the native `wire` lines) and
// replay reproduces it: hosts in any SPI mode, bit order, word size, speed and cs_change use,
// timed or untimed CS edges, record and replay with no divergence.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "daisychain/recording_chain.hpp"
#include "daisychain/replay.hpp"
#include "spi/message.hpp"
#include "spi/trace_native.hpp"

namespace l6470emu {
namespace {

using Bytes = std::vector<std::uint8_t>;

/// The recording written as native text, read back and replayed against a fresh chain.
ReplayResult replay_text(const std::string& text, std::size_t chips) {
  NativeTraceReader reader(text, "wire.trace");
  Chain fresh(chips);
  return replay_trace(reader, fresh);
}

std::string first_report(const ReplayResult& r) { return r.divergences.empty() ? "" : r.divergences[0].report; }

/// One spidev-like message of one-byte transfers with cs_change between them (a frame per byte).
void bytes_as_frames(SpiDevice& dev, const Bytes& tx, Bytes& rx, const BusTiming& timing) {
  rx.assign(tx.size(), 0);
  std::vector<SpiTransfer> t(tx.size());
  for (std::size_t i = 0; i < tx.size(); ++i) {
    t[i].tx = std::span<const std::uint8_t>(&tx[i], 1);
    t[i].rx = std::span<std::uint8_t>(&rx[i], 1);
    t[i].len = 1;
    t[i].cs_change = i + 1 < tx.size();
  }
  run_message(dev, t, timing);
}

TEST(WireReplay, AModeZeroHostsGetStatusRecordedAsFcReplaysWithNoDivergence) {
  // The case: GetStatus a byte per frame in SPI mode 0 reads the stale SDO latch as the
  // first bit of the answer: 0xFC where mode 3 reads 0x7C; a replay in mode 3 diverged there.
  Chain chain(1);
  Trace trace;
  RecordingChain rec(chain, trace, RecordOptions{.observe_outputs = false, .board = {}});
  BusTiming timing;
  timing.wire.mode = 0;
  Bytes rx;
  bytes_as_frames(rec, {0xD0, 0x00, 0x00}, rx, timing);
  ASSERT_EQ(trace.frame_count(), 3u);
  EXPECT_EQ(rx[1], 0xFC);
  EXPECT_TRUE(trace[1].wire.known);
  EXPECT_EQ(trace[1].wire.mode, 0);
  const std::string text = to_native_text(trace);
  EXPECT_NE(text.find(" wire mode=0 order=msb bits=8 speed=5000000 deselect=timed\n"), std::string::npos) << text;
  const ReplayResult r = replay_text(text, 1);
  EXPECT_TRUE(r.matched()) << first_report(r);
  EXPECT_EQ(r.bytes_compared, 3u);
}

TEST(WireReplay, EveryModeBitOrderWordSizeSpeedAndCsChangeRecordsAndReplaysWithNoDivergence) {
  // Random commands to a 3-chip chain in messages of random shapes, the host's settings changed
  // between messages: the recording, written as text and read back, replays byte for byte.
  std::mt19937 rng(17);
  Chain chain(3);
  Trace trace;
  RecordingChain rec(chain, trace, RecordOptions{.observe_outputs = false, .board = {}});
  static constexpr std::uint8_t kCommands[] = {0xD0, 0x00, 0x27, 0x05, 0x25, 0x38, 0x50, 0xB8, 0x40, 0x21, 0xC0};
  for (unsigned mode = 0; mode < 4; ++mode)
    for (bool lsb : {false, true})
      for (unsigned bits : {8u, 16u, 32u})
        for (std::uint32_t hz : {400'000u, 5'000'000u, 10'000'000u})
          for (bool cs_change : {false, true}) {
            BusTiming timing;
            timing.wire.mode = static_cast<std::uint8_t>(mode);
            timing.wire.lsb_first = lsb;
            timing.wire.bits_per_word = static_cast<std::uint8_t>(bits);
            timing.default_speed_hz = hz;
            const std::size_t w = bits / 8, words = 1 + rng() % 4;
            Bytes tx(w * words), rx(tx.size());
            for (auto& b : tx) b = kCommands[rng() % std::size(kCommands)];
            std::vector<SpiTransfer> t(words);
            for (std::size_t i = 0; i < words; ++i) {
              t[i].tx = std::span<const std::uint8_t>(tx.data() + i * w, w);
              t[i].rx = std::span<std::uint8_t>(rx.data() + i * w, w);
              t[i].len = static_cast<std::uint32_t>(w);
              t[i].cs_change = cs_change && i + 1 < words;
            }
            run_message(rec, t, timing);
            rec.advance_to(rec.now() + rng() % 2000);
          }
  const std::string text = to_native_text(trace, true);
  for (unsigned mode = 0; mode < 4; ++mode)
    EXPECT_NE(text.find(" wire mode=" + std::to_string(mode) + " order=lsb bits=32 speed=10000000 deselect=timed\n"),
              std::string::npos);
  const ReplayResult r = replay_text(text, 3);
  EXPECT_TRUE(r.matched()) << first_report(r);
  EXPECT_GE(r.frames, 144u);
}

TEST(WireReplay, ADeselectShorterThanTDisCsIsReplayedAsTheTimedHostSawIt) {
  // CS high for 1 tick between frames: the chips decode but do not load their answers, and the
  // next byte clocks out the byte each received (the echo). The recording's frame times say so,
  // and its `wire` line says that the CS edges were timed.
  Chain chain(1);
  Trace trace;
  RecordingChain rec(chain, trace, RecordOptions{.observe_outputs = false, .board = {}});
  BusTiming timing;
  timing.cs_high_ticks = 1;
  Bytes rx;
  bytes_as_frames(rec, {0xD0, 0x00, 0x00, 0x27, 0x00, 0x00}, rx, timing);
  EXPECT_EQ(rx[1], 0xD0);  // the echo of GetStatus, not its answer
  const ReplayResult r = replay_text(to_native_text(trace), 1);
  EXPECT_TRUE(r.matched()) << first_report(r);
}

TEST(WireReplay, AnUntimedHostsBackToBackFramesReplayWithoutTheEcho) {
  // A front whose time moves only when told (Python's Chain.frame) selects through the byte face:
  // no t_disCS, however close its frames, and a replay must not invent one.
  Chain chain(1);
  Trace trace;
  RecordingChain rec(chain, trace, RecordOptions{.observe_outputs = false, .board = {}});
  WireSettings wire;
  wire.mode = 1;
  Bytes out;
  for (std::uint8_t b : {0xD0, 0x00, 0x00, 0x38, 0x00}) {
    std::uint8_t in = 0;
    rec.select();
    rec.exchange_wire(std::span<const std::uint8_t>(&b, 1), std::span<std::uint8_t>(&in, 1), wire);
    rec.deselect_wire();
    out.push_back(in);
  }
  const std::string text = to_native_text(trace);
  EXPECT_NE(text.find(" wire mode=1 order=msb bits=8 speed=0 deselect=untimed\n"), std::string::npos) << text;
  const ReplayResult r = replay_text(text, 1);
  EXPECT_TRUE(r.matched()) << first_report(r);
}

TEST(WireReplay, AByteFaceRecordingHasNoWireLineAndReplaysAsBefore) {
  Chain chain(2);
  Trace trace;
  RecordingChain rec(chain, trace, RecordOptions{.observe_outputs = false, .board = {}});
  for (int i = 0; i < 3; ++i) {
    rec.select();
    Bytes tx{0xD0, 0xD0}, rx(2);
    rec.exchange(tx, rx);
    rec.deselect();
  }
  const std::string text = to_native_text(trace);
  EXPECT_EQ(text.find(" wire "), std::string::npos) << text;
  EXPECT_FALSE(trace[0].wire.known);
  EXPECT_TRUE(replay_text(text, 2).matched());
}

}  // namespace
}  // namespace l6470emu
