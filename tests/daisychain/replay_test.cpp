// Replay (daisychain/replay.hpp): captured MISO compared byte by byte with the emulated
// chain; reports with frame number, time, each chip's command, expected vs emulated bytes
// and the chip state; --continue; BUSY/FLAG observations; the shipped fixtures.
#include <gtest/gtest.h>

#include "daisychain/chain_spec.hpp"
#include "daisychain/replay.hpp"
#include "spi/trace_import.hpp"
#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

ReplayResult replay_text(const std::string& text, std::size_t chips, ReplayOptions o = {}) {
  NativeTraceReader r(text, "t.trace");
  Chain chain(chips);
  return replay_trace(r, chain, o);
}

const std::string kGetStatus =
    "l6470emu-trace 1\n"
    "0.00000200 frame 1.75us D0 | 00\n"
    "0.00000500 frame 1.75us 00 | 7C\n"
    "0.00000800 frame 1.75us 00 | 03\n";

TEST(Replay, MatchesACaptureOfThePowerUpStatus) {
  const ReplayResult r = replay_text(kGetStatus, 1);
  EXPECT_TRUE(r.matched());
  EXPECT_EQ(r.frames, 3u);
  EXPECT_EQ(r.bytes_compared, 3u);
}

TEST(Replay, ReportsTheFirstDivergenceWithEverythingNeededToUnderstandIt) {
  std::string text = kGetStatus;
  text.replace(text.find("| 7C"), 4, "| 7E");  // the real chip had its UVLO flag cleared already
  const ReplayResult r = replay_text(text, 1);
  ASSERT_FALSE(r.matched());
  EXPECT_TRUE(r.stopped_early);
  ASSERT_EQ(r.divergences.size(), 1u);
  const Divergence& d = r.divergences[0];
  EXPECT_EQ(d.frame, 2u);
  EXPECT_EQ(d.line, 3u);
  EXPECT_EQ(d.summary, "t.trace:3: frame 2 at t=0.00000500 s: MISO byte 0 expected 0x7E, emulated 0x7C");
  const std::string& rep = d.report;
  EXPECT_NE(rep.find("  MOSI      00\n  expected  7E\n  emulated  7C\n            ^^\n"), std::string::npos) << rep;
  EXPECT_NE(rep.find("byte 0: chip 0: byte 1 of 2 of the GetStatus answer (decoded in frame 1, t=0.000002 s)"),
            std::string::npos)
      << rep;
  EXPECT_NE(rep.find("chip 0: decodes 0x00 = NOP"), std::string::npos) << rep;
  EXPECT_NE(rep.find("chip 0 state (emulated, as it answered):\n    L6470 at tick 20"), std::string::npos) << rep;
  EXPECT_NE(rep.find("STATUS     = 0x7E03  [HiZ REV STOPPED]"), std::string::npos) << rep;
}

TEST(Replay, GoesOnWithContinueAndCountsEveryDivergentFrame) {
  std::string text = kGetStatus;
  text.replace(text.find("| 7C"), 4, "| 7E");
  text.replace(text.find("| 03"), 4, "| 13");
  ReplayOptions o;
  o.keep_going = true;
  const ReplayResult r = replay_text(text, 1, o);
  EXPECT_FALSE(r.stopped_early);
  EXPECT_EQ(r.divergent_frames, 2u);
  EXPECT_EQ(r.divergences.size(), 2u);
  o.max_reports = 1;
  const ReplayResult capped = replay_text(text, 1, o);
  EXPECT_EQ(capped.divergent_frames, 2u);
  EXPECT_EQ(capped.divergences.size(), 1u);
}

TEST(Replay, DescribesWhatEachChipOfAChainIsDecoding) {
  // Chip 1 collects a Move's argument bytes while chip 0 answers GetParam(ABS_POS).
  std::string text =
      "l6470emu-trace 1\n"
      "0.00001 frame 21 41 | 00 00\n"
      "0.00002 frame 00 00 | 00 00\n"
      "0.00003 frame 00 01 | 55 00\n";
  ReplayOptions o;
  const ReplayResult r = replay_text(text, 2, o);
  ASSERT_EQ(r.divergences.size(), 1u);
  const std::string& rep = r.divergences[0].report;
  EXPECT_NE(rep.find("byte 0: chip 0: byte 2 of 3 of the GetParam(ABS_POS) answer"), std::string::npos) << rep;
  EXPECT_NE(rep.find("chip 0: decodes 0x00 = NOP"), std::string::npos) << rep;
  EXPECT_NE(rep.find("chip 1: argument byte 2 of 3 of Move(FWD) = 0x01"), std::string::npos) << rep;
}

TEST(Replay, HintsAtALongerRealChainWhenBytesBeyondTheChainDiffer) {
  // A real 2-chip chain answers in both slots; emulated as one chip, slot 1 is an echo.
  const std::string text = "l6470emu-trace 1\n0 frame D0 D0 | 00 00\n0.00001 frame 00 00 | 7C 7C\n";
  const ReplayResult r = replay_text(text, 1);
  ASSERT_EQ(r.divergences.size(), 1u);
  EXPECT_NE(r.divergences[0].report.find("is the real chain longer? see --chain"), std::string::npos)
      << r.divergences[0].report;
}

TEST(Replay, ComparesBusyAndFlagObservations) {
  const std::string text =
      "l6470emu-trace 1\n"
      "0 pin 0 FLAG 0\n"
      "0 pin 0 BUSY 0\n";
  const ReplayResult r = replay_text(text, 1);
  EXPECT_EQ(r.pin_checks, 2u);
  ASSERT_EQ(r.pin_mismatches, 1u);
  EXPECT_EQ(r.divergences[0].summary,
            "t.trace:3: t=0.00000000 s (after frame 0): chip 0 BUSY expected low (busy), emulated high (released)");
  ReplayOptions o;
  o.compare_pins = false;
  EXPECT_TRUE(replay_text(text, 1, o).matched());
}

TEST(Replay, AppliesPinsAndFaultsFromTheTrace) {
  const std::string text =
      "l6470emu-trace 1\n"
      "0.001 fault 0 UVLO off\n"
      "0.002 fault 0 OCD on\n"
      "0.003 frame D0 | 00\n"
      "0.004 frame 00 | 6C\n"  // OCD (bit 12 low) and UVLO latched since power-up
      "0.005 frame 00 | 03\n";
  EXPECT_TRUE(replay_text(text, 1).matched());
}

TEST(Replay, RejectsEventsForChipsOutsideTheChain) {
  try {
    replay_text("l6470emu-trace 1\n0 pin 4 SW 0\n", 3);
    FAIL();
  } catch (const TraceError& e) {
    EXPECT_EQ(std::string(e.what()), "t.trace:2: event for chip 4 (trace files count from the MISO end), but the chain has 3 chips (see --chain)");
  }
}

TEST(Replay, MatchesTheRecordedFixtures) {
  for (const char* name : {"three_chips.trace", "single_chip.trace"}) {
    const std::string text = test::fixture(name);
    NativeTraceReader r(text, name);
    Chain chain = make_chain(parse_chain_spec(r.header().chain));
    const ReplayResult res = replay_trace(r, chain);
    EXPECT_TRUE(res.matched()) << name << (res.divergences.empty() ? "" : "\n" + res.divergences[0].report);
  }
}

TEST(Replay, MatchesTheImportedCapturesThatCarryTheirTiming) {
  struct Case {
    const char* name;
    std::size_t chips;
  };
  for (const Case c : {Case{"saleae_logic2.csv", 1}, Case{"saleae_logic2_decimal_no_duration.csv", 1},
                       Case{"ftrace_trace_cmd_report.txt", 2}, Case{"sigrok_spi.json", 2}}) {
    const Trace t = import_trace(test::fixture(c.name), c.name,
                                 detect_trace_format(test::fixture(c.name), c.name));
    auto r = t.reader();
    Chain chain(c.chips);
    const ReplayResult res = replay_trace(*r, chain);
    EXPECT_TRUE(res.matched()) << c.name << (res.divergences.empty() ? "" : "\n" + res.divergences[0].report);
    EXPECT_EQ(res.bytes_compared, t.frame_count() * c.chips) << c.name;
  }
}

TEST(Replay, DivergesWhereTheCaptureMissesTheWorldOutsideSpi) {
  // The 3-chip session's switch closing on chip 0 is not in the kernel's SPI trace: the first
  // answer after it differs, at ABS_POS, which GoUntil reset when the switch closed.
  const Trace t = import_ftrace(test::fixture("ftrace_spi_set_cs.txt"), "ftrace_spi_set_cs.txt");
  auto r = t.reader();
  Chain chain(3);
  const ReplayResult res = replay_trace(*r, chain);
  ASSERT_FALSE(res.matched());
  EXPECT_EQ(res.divergences[0].summary,
            "ftrace_spi_set_cs.txt:169: frame 23 at t=1523.803136000 s: MISO byte 0 expected 0xF0, emulated 0xCD");
  // umockdev recordings have no times: the host's 20 ms wait after its Move is lost.
  const Trace u = import_umockdev_ioctl(test::fixture("umockdev_spidev.ioctl"), "umockdev_spidev.ioctl");
  auto ur = u.reader();
  Chain one(1);
  const ReplayResult ures = replay_trace(*ur, one);
  ASSERT_FALSE(ures.matched());
  EXPECT_EQ(ures.divergences[0].frame, 26u);
}

}  // namespace
}  // namespace l6470emu
