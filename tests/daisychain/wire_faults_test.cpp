// The wire's one-shot faults on a chain (Chain::arm_miso_flip, arm_lost_frame) and a chip's
// brown-out as the chain sees it (Chain::power_cycle): what the host reads, what each chip
// decodes, on the byte path and the bit-level one, and their recordings replayed. Each run
// is compared with a twin chain that got no fault.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "daisychain/chain.hpp"
#include "daisychain/replay.hpp"
#include "spi/trace_native.hpp"
#include "spi/wire.hpp"
#include "support/test_support.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;
using Bytes = std::vector<std::uint8_t>;

constexpr std::uint8_t kKvalRunReset = 0x29;

/// Two chains fed the same frames; only `hit` gets the faults.
struct Twins {
  Chain hit, ref;
  explicit Twins(std::size_t n) : hit(n), ref(n) {}
  /// One frame to both; returns (hit's MISO, ref's MISO).
  std::pair<Bytes, Bytes> frame(const Bytes& tx) { return {hit.frame(tx), ref.frame(tx)}; }
};

// ---------------------------------------------------------------- miso_flip

TEST(MisoFlip, InvertsOneBitOfTheNextFramesAnswerByteOfThatChipInAThreeChipChain) {
  Twins t(3);
  t.frame({0xD0, 0xD0, 0xD0});  // GetStatus everywhere: the answers' MSBs wait in the registers
  t.hit.arm_miso_flip(1, 7);
  const auto [hit, ref] = t.frame({0x00, 0x00, 0x00});
  ASSERT_EQ(hit.size(), 3u);
  EXPECT_EQ(hit[0], ref[0]);
  EXPECT_EQ(hit[1], ref[1] ^ 0x80u) << "bit 7 of chip 1's byte, and no other";
  EXPECT_EQ(hit[2], ref[2]);
  // The next frame is clean, and no chip was touched.
  const auto [hit2, ref2] = t.frame({0x00, 0x00, 0x00});
  EXPECT_EQ(hit2, ref2);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(t.hit.chip(k).status(), t.ref.chip(k).status()) << "chip " << k;
}

TEST(MisoFlip, FlipsTheBitItNames) {
  for (std::uint8_t bit = 0; bit < 8; ++bit) {
    Twins t(1);
    t.frame({0xD0});
    t.hit.arm_miso_flip(0, bit);
    const auto [hit, ref] = t.frame({0x00});
    EXPECT_EQ(hit[0] ^ ref[0], 1u << bit) << "bit " << int(bit);
  }
}

TEST(MisoFlip, ArmedWhileCsIsLowActsOnTheFollowingFrame) {
  Twins t(2);
  t.hit.select();
  t.ref.select();
  EXPECT_EQ(t.hit.exchange(0xD0), t.ref.exchange(0xD0));
  t.hit.arm_miso_flip(0, 0);
  EXPECT_EQ(t.hit.exchange(0xD0), t.ref.exchange(0xD0)) << "this frame started before the fault";
  t.hit.deselect();
  t.ref.deselect();
  const auto [hit, ref] = t.frame({0x00, 0x00});
  EXPECT_EQ(hit[0], ref[0] ^ 0x01u);
  EXPECT_EQ(hit[1], ref[1]);
}

TEST(MisoFlip, ACsPulseWithoutClocksLeavesItArmed) {
  Twins t(1);
  t.frame({0xD0});
  t.hit.arm_miso_flip(0, 7);
  t.hit.select();
  t.hit.deselect();
  const auto [hit, ref] = t.frame({0x00});
  EXPECT_EQ(hit[0], ref[0] ^ 0x80u);
}

TEST(MisoFlip, WorksByteByByteAndOnAFrameLongerThanTheChain) {
  Twins t(2);
  t.frame({0xD0, 0xD0});
  t.hit.arm_miso_flip(1, 6);
  t.hit.select();
  t.ref.select();
  Bytes hit, ref;
  for (int i = 0; i < 4; ++i) {  // 4 bytes through 2 chips: chip 1's answer is byte 1
    hit.push_back(t.hit.exchange(0x00));
    ref.push_back(t.ref.exchange(0x00));
  }
  t.hit.deselect();
  t.ref.deselect();
  EXPECT_EQ(hit[0], ref[0]);
  EXPECT_EQ(hit[1], ref[1] ^ 0x40u);
  EXPECT_EQ(hit[2], ref[2]);
  EXPECT_EQ(hit[3], ref[3]);
}

TEST(MisoFlip, ActsOnTheBytesTheHostReadsOnTheBitLevelPath) {
  for (std::uint8_t mode : {0, 1, 2, 3}) {
    for (bool lsb : {false, true}) {
      WireSettings w;
      w.mode = mode;
      w.lsb_first = lsb;
      Chain hit(3), ref(3);
      Bytes rh(3), rr(3);
      const Bytes get_status{0xD0, 0xD0, 0xD0}, nops{0x00, 0x00, 0x00};
      hit.frame(get_status, rh, w);
      ref.frame(get_status, rr, w);
      hit.arm_miso_flip(2, 5);
      hit.frame(nops, rh, w);
      ref.frame(nops, rr, w);
      EXPECT_EQ(rh[0], rr[0]) << "mode " << int(mode) << (lsb ? " lsb" : "");
      EXPECT_EQ(rh[1], rr[1]) << "mode " << int(mode) << (lsb ? " lsb" : "");
      EXPECT_EQ(rh[2], rr[2] ^ 0x20u) << "mode " << int(mode) << (lsb ? " lsb" : "");
      hit.frame(nops, rh, w);
      ref.frame(nops, rr, w);
      EXPECT_EQ(rh, rr) << "a later frame is clean; mode " << int(mode) << (lsb ? " lsb" : "");
    }
  }
}

TEST(MisoFlip, ActsOnASingleByteFrameOfTheBitLevelFace) {
  Chain hit(1), ref(1);
  const WireSettings w;  // mode 3, MSB first: the one-byte fast path of exchange_wire
  std::uint8_t rh = 0, rr = 0;
  const std::uint8_t d0 = 0xD0, nop = 0x00;
  using In = std::span<const std::uint8_t>;
  using Out = std::span<std::uint8_t>;
  hit.frame(In(&d0, 1), Out(&rh, 1), w);
  ref.frame(In(&d0, 1), Out(&rr, 1), w);
  hit.arm_miso_flip(0, 1);
  hit.frame(In(&nop, 1), Out(&rh, 1), w);
  ref.frame(In(&nop, 1), Out(&rr, 1), w);
  EXPECT_EQ(rh, rr ^ 0x02u);
}

// ---------------------------------------------------------------- lost_frame

TEST(LostFrame, TheChipMissesExactlyOneSetParamWhileTheChipsBeforeItSeeIt) {
  Chain chain(3);
  chain.arm_lost_frame(0);
  chain.frame(Bytes{0x0A, 0x0A, 0x0A});  // SetParam(KVAL_RUN): chip 0 never sees it
  chain.frame(Bytes{0x00, 0x22, 0x33});  // the values; to chip 0 a NOP
  EXPECT_EQ(chain.chip(0).peek(Reg::KVAL_RUN), kKvalRunReset) << "not applied";
  EXPECT_FALSE(chain.chip(0).collecting_arguments());
  EXPECT_EQ(chain.chip(1).peek(Reg::KVAL_RUN), 0x22u);
  EXPECT_EQ(chain.chip(2).peek(Reg::KVAL_RUN), 0x33u);
  // One frame only: the next SetParam reaches it.
  chain.frame(Bytes{0x0A, 0x0A, 0x0A});
  chain.frame(Bytes{0x44, 0x55, 0x66});
  EXPECT_EQ(chain.chip(0).peek(Reg::KVAL_RUN), 0x44u);
}

TEST(LostFrame, BreaksTheChainForThatFrameAsAChipInStandbyDoes) {
  // The bytes for the chips between it and MISO pass through it: they get 0x00 (a NOP) instead.
  Chain chain(3);
  chain.arm_lost_frame(2);
  chain.frame(Bytes{0x0A, 0x0A, 0x0A});
  chain.frame(Bytes{0x11, 0x22, 0x33});  // to chip 2 an opcode of its own (no SetParam waits)
  EXPECT_EQ(chain.chip(0).peek(Reg::KVAL_RUN), kKvalRunReset);
  EXPECT_EQ(chain.chip(1).peek(Reg::KVAL_RUN), kKvalRunReset);
  EXPECT_EQ(chain.chip(2).peek(Reg::KVAL_RUN), kKvalRunReset);
}

TEST(LostFrame, AGetStatusItMissesIsNotAnsweredAndClearsNothing) {
  Chain chain(3);
  chain.arm_lost_frame(0);
  const Bytes during = chain.frame(Bytes{0xD0, 0xD0, 0xD0});
  EXPECT_EQ(during[0], 0x00) << "it drives nothing";
  const Bytes answers = chain.frame(Bytes{0x00, 0x00, 0x00});
  EXPECT_EQ(answers[0], 0x00) << "no answer from chip 0";
  EXPECT_NE(answers[1], 0x00);
  EXPECT_NE(answers[2], 0x00);
  EXPECT_EQ(chain.chip(0).status() & kUvloN, 0) << "chip 0's power-up UVLO is still latched";
  EXPECT_NE(chain.chip(1).status() & kUvloN, 0) << "chip 1's GetStatus cleared it";
  EXPECT_NE(chain.chip(2).status() & kUvloN, 0);
}

TEST(LostFrame, TheChipKeepsTheByteItsRegisterHeldAndShiftsItOutNextFrame) {
  Chain chain(2);
  chain.frame(Bytes{0x2A, 0x2A});  // GetParam(KVAL_RUN): the answers load at CS rising
  chain.arm_lost_frame(0);
  const Bytes lost = chain.frame(Bytes{0x00, 0x00});
  EXPECT_EQ(lost, (Bytes{0x00, 0x00})) << "chip 0 shifts nothing out, and chip 1's answer stops at it";
  const Bytes next = chain.frame(Bytes{0x00, 0x00});
  EXPECT_EQ(next, (Bytes{kKvalRunReset, 0x00})) << "chip 0's answer waited in its register";
}

TEST(LostFrame, LeavesTheChipsStateAndMotionUntouched) {
  Twins t(1);
  t.frame({0xD0});
  t.frame({0x00});
  t.frame({0x51});  // Run forward: SPD follows in 3 bytes
  t.frame({0x00});
  t.frame({0x20});
  t.frame({0x00});
  t.hit.advance_to(ticks_from_ms(100));
  t.ref.advance_to(ticks_from_ms(100));
  t.hit.arm_lost_frame(0);
  t.frame({0xA8});  // HardHiZ: chip 0 of `hit` misses it
  EXPECT_FALSE(t.hit.chip(0).hiz());
  EXPECT_TRUE(t.ref.chip(0).hiz());
  EXPECT_EQ(t.hit.chip(0).position(), t.ref.chip(0).position());
  EXPECT_NE(t.hit.chip(0).position(), 0);
}

TEST(LostFrame, ACsPulseWithoutClocksLeavesItArmed) {
  Chain chain(1);
  chain.frame(Bytes{0x2A});
  chain.arm_lost_frame(0);
  chain.select();
  chain.deselect();
  EXPECT_EQ(chain.frame(Bytes{0x00}), Bytes{0x00});
  EXPECT_EQ(chain.frame(Bytes{0x00}), Bytes{kKvalRunReset});
}

TEST(LostFrame, TheBitLevelPathMissesTheFrameToo) {
  WireSettings w;
  w.mode = 0;
  Chain chain(2);
  Bytes rx(2);
  chain.arm_lost_frame(0);
  chain.frame(Bytes{0x0A, 0x0A}, rx, w);
  chain.frame(Bytes{0x00, 0x22}, rx, w);
  EXPECT_EQ(chain.chip(0).peek(Reg::KVAL_RUN), kKvalRunReset);
  EXPECT_EQ(chain.chip(1).peek(Reg::KVAL_RUN), 0x22u);
}

// ---------------------------------------------------------------- power cycle

TEST(ChainPowerCycle, EmptiesTheChipsRegisterAndLatchesUvlo) {
  Chain chain(2);
  chain.frame(Bytes{0xD0, 0xD0});
  chain.frame(Bytes{0x00, 0x00});  // UVLO cleared everywhere
  chain.frame(Bytes{0x2A, 0x2A});  // answers wait in the registers
  chain.power_cycle(1);
  const Bytes rx = chain.frame(Bytes{0x00, 0x00});
  EXPECT_EQ(rx, (Bytes{kKvalRunReset, 0x00})) << "chip 1's answer went with the power";
  EXPECT_EQ(chain.chip(1).status() & kUvloN, 0);
  EXPECT_NE(chain.chip(0).status() & kUvloN, 0);
}

TEST(ChainPowerCycle, WithCsLowHappensAtTheCsRisingEdgeAfterTheChipsDecode) {
  Chain chain(1);
  chain.select();
  chain.exchange(0x0A);  // SetParam(KVAL_RUN) ...
  chain.power_cycle(0);
  chain.deselect();      // ... decoded, then the power goes
  EXPECT_FALSE(chain.chip(0).collecting_arguments());
  chain.frame(Bytes{0x66});   // an opcode of its own now
  EXPECT_EQ(chain.chip(0).peek(Reg::KVAL_RUN), kKvalRunReset);
}

// ---------------------------------------------------------------- recorded and replayed

std::vector<std::string> lines_without_time(const Trace& trace) {
  std::vector<std::string> lines;
  for (std::size_t i = 0; i < trace.size(); ++i) {
    const std::string l = NativeTraceWriter::format_event(trace[i]);
    lines.push_back(l.substr(l.find(' ') + 1));
  }
  return lines;
}

bool has_line(const std::vector<std::string>& lines, const std::string& line) {
  return std::find(lines.begin(), lines.end(), line) != lines.end();
}

ReplayResult replay_text(const std::string& text, std::size_t chips) {
  NativeTraceReader reader(text, "faults.trace");
  Chain fresh(chips);
  return replay_trace(reader, fresh);
}

TEST(WireFaultsRecorded, EachOfTheThreeReplaysWithoutDivergence) {
  test::RecordedSession s(3);
  s.each({0xD0, 0x00, 0x00});
  s.frame({0x2A, 0x2A, 0x2A});  // GetParam(KVAL_RUN) everywhere: the answers wait in the registers
  s.rec.miso_flip(1, 3);
  const Bytes flipped = s.frame({0x00, 0x00, 0x00});
  EXPECT_EQ(flipped[1], kKvalRunReset ^ 0x08u);
  s.rec.lost_frame(2);
  s.each({0x0A, 0x77});  // SetParam(KVAL_RUN, 0x77): chip 2 misses the opcode, and chips 0, 1 with it
  s.rec.power_cycle(0);
  s.each({0xD0, 0x00, 0x00});
  // Injected with CS low: recorded after the frame, acting on the next one in both runs.
  s.rec.select();
  s.rec.exchange(0x00);
  s.rec.miso_flip(0, 0);
  s.rec.lost_frame(1);
  s.rec.power_cycle(2);
  s.rec.exchange(0x00);
  s.rec.exchange(0x00);
  s.rec.deselect();
  s.each({0x2A, 0x00});
  s.wait_ms(5);
  const std::vector<std::string> lines = lines_without_time(s.trace);
  EXPECT_TRUE(has_line(lines, "fault 1 MISO_FLIP 3")) << ::testing::PrintToString(lines);
  EXPECT_TRUE(has_line(lines, "fault 2 LOST_FRAME"));
  EXPECT_TRUE(has_line(lines, "fault 0 POWER_CYCLE"));
  EXPECT_TRUE(has_line(lines, "fault 2 POWER_CYCLE"));
  const std::string text = to_native_text(s.trace);
  const ReplayResult r = replay_text(text, 3);
  EXPECT_TRUE(r.matched()) << (r.divergences.empty() ? "" : r.divergences[0].report);
  EXPECT_EQ(r.divergent_frames, 0u);
  EXPECT_GT(r.bytes_compared, 30u);
}

/// `text` without the lines that contain `what`.
std::string without(std::string text, const std::string& what) {
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what)) {
    const std::size_t from = text.rfind('\n', at) + 1;
    text.erase(from, text.find('\n', at) + 1 - from);
  }
  return text;
}

TEST(WireFaultsRecorded, AReplayWithoutTheFaultLinesDiverges) {
  // The replay applies each fault: without its line the host-visible bytes differ.
  for (const std::string fault : {"MISO_FLIP", "LOST_FRAME", "POWER_CYCLE"}) {
    test::RecordedSession s(2);
    s.each({0xD0, 0x00, 0x00});
    s.frame({0x2A, 0x2A});
    if (fault == "MISO_FLIP") s.rec.miso_flip(0, 7);
    if (fault == "LOST_FRAME") s.rec.lost_frame(0);
    if (fault == "POWER_CYCLE") s.rec.power_cycle(0);
    s.frame({0x00, 0x00});
    s.each({0xD0, 0x00, 0x00});
    const std::string text = to_native_text(s.trace);
    ASSERT_NE(text.find(fault), std::string::npos);
    EXPECT_TRUE(replay_text(text, 2).matched()) << fault;
    EXPECT_FALSE(replay_text(without(text, fault), 2).matched()) << fault;
  }
}

TEST(WireFaultsRecorded, TheNativeLinesReadBack) {
  const std::string text =
      "l6470emu-trace 2\nchain 2*L6470\n"
      "0.00000100 fault 1 MISO_FLIP 7\n0.00000200 fault 0 LOST_FRAME\n0.00000300 fault 1 POWER_CYCLE\n";
  const Trace t = read_native_trace(text, "x");
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[0].fault, TraceFault::MISO_FLIP);
  EXPECT_EQ(t[0].value, 7u);
  EXPECT_EQ(t[1].fault, TraceFault::LOST_FRAME);
  EXPECT_EQ(t[2].fault, TraceFault::POWER_CYCLE);
  EXPECT_EQ(to_native_text(t).substr(to_native_text(t).find("0.00000100")), text.substr(text.find("0.00000100")));
  EXPECT_THROW(read_native_trace("l6470emu-trace 2\nchain 1*L6470\n0.1 fault 0 MISO_FLIP 8\n", "x"), TraceError);
  EXPECT_THROW(read_native_trace("l6470emu-trace 2\nchain 1*L6470\n0.1 fault 0 LOST_FRAME on\n", "x"), TraceError);
}

}  // namespace
}  // namespace l6470emu
