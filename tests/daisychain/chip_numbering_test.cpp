// Chip numbering (daisychain/chip_numbering.hpp) and the reports that use it: with chip 0 at
// the MOSI end, decode, replay and motion series name the chip nearest the host's MOSI
// "chip 0" while the chain's own indices stay MISO-based.
#include <gtest/gtest.h>

#include <sstream>
#include <stdexcept>

#include "daisychain/chain_spec.hpp"
#include "daisychain/chip_numbering.hpp"
#include "daisychain/decode.hpp"
#include "daisychain/host.hpp"
#include "daisychain/motion_series.hpp"
#include "daisychain/recording_chain.hpp"
#include "daisychain/replay.hpp"
#include "spi/trace_native.hpp"

namespace l6470emu {
namespace {

/// A native trace of one CS frame per line ("mosi bytes | miso bytes"), 10 µs apart.
std::string frames(const std::vector<std::string>& lines) {
  std::string t = "l6470emu-trace 1\n";
  Tick tick = 4;
  for (const std::string& l : lines) {
    t += format_seconds(tick) + " frame 5.75us " + l + "\n";
    tick += 40;
  }
  return t;
}

std::string decode_log(const std::string& text, std::size_t chips, DecodeOptions o) {
  NativeTraceReader r(text, "t.trace");
  Chain chain(chips);
  std::ostringstream out;
  decode_trace(r, chain, out, o);
  return out.str();
}

// Byte 2 of each 3-byte frame reaches the chip nearest MOSI (the chain's chip 2): a Move.
const std::vector<std::string> kMoveOfTheMosiEndChip = {"00 00 41 | 00 00 00", "00 00 00 | 00 00 00",
                                                       "00 00 0C | 00 00 00", "00 00 80 | 00 00 00"};

TEST(ChipNumbering, FromMisoKeepsTheChainsOwnIndices) {
  const ChipNumbering n(NumberFrom::miso, 3);
  EXPECT_EQ(n.number_of(0), 0u);
  EXPECT_EQ(n.number_of(2), 2u);
  EXPECT_EQ(n.index_of(1), 1u);
  EXPECT_EQ(n.label(2), "chip 2");
}

TEST(ChipNumbering, FromMosiCallsTheChipNearestMosiChipZero) {
  const ChipNumbering n(NumberFrom::mosi, 3);
  EXPECT_EQ(n.number_of(2), 0u);  // the chain's chip 2 reads the host's MOSI
  EXPECT_EQ(n.number_of(0), 2u);  // the chain's chip 0 drives MISO
  EXPECT_EQ(n.index_of(0), 2u);
  EXPECT_EQ(n.index_of(1), 1u);
  EXPECT_EQ(n.label(0), "chip 2");
}

TEST(ChipNumbering, SaysWhichEndChipZeroIsAt) {
  EXPECT_EQ(describe_numbering(NumberFrom::miso),
            "chip numbers count from the MISO end (chip 0 drives MISO and gets a full frame's first byte)");
  EXPECT_EQ(describe_numbering(NumberFrom::mosi),
            "chip numbers count from the MOSI end (chip 0 reads the host's MOSI and gets a full frame's last byte)");
}

TEST(ChipNumbering, ReadsMisoAndMosiInAnyCaseAndRejectsAnythingElseInOneLine) {
  EXPECT_EQ(parse_number_from("miso"), NumberFrom::miso);
  EXPECT_EQ(parse_number_from("MOSI"), NumberFrom::mosi);
  try {
    parse_number_from("x");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "'x' is not a chip numbering: write miso (chip 0 drives MISO) or mosi (chip 0 reads the host's MOSI)");
  }
  EXPECT_THROW(parse_number_from(""), std::invalid_argument);
  EXPECT_THROW(parse_number_from(std::string("mi\0so", 5)), std::invalid_argument);
}

TEST(ChipNumberingInDecode, ShowsTheMosiEndChipAsChipZero) {
  DecodeOptions o;
  o.number_from = NumberFrom::mosi;
  const std::string log = decode_log(frames(kMoveOfTheMosiEndChip), 3, o);
  EXPECT_NE(log.find("chip 0   Move(FWD, 3200 microsteps)"), std::string::npos) << log;
  EXPECT_EQ(log.find("chip 2   Move"), std::string::npos) << log;
}

TEST(ChipNumberingInDecode, KeepsTheMisoEndAsChipZeroByDefault) {
  const std::string log = decode_log(frames(kMoveOfTheMosiEndChip), 3, {});
  EXPECT_NE(log.find("chip 2   Move(FWD, 3200 microsteps)"), std::string::npos) << log;
}

TEST(ChipNumberingInDecode, FiltersOnTheUsersChipNumber) {
  DecodeOptions o;
  o.number_from = NumberFrom::mosi;
  o.only_chip = 0;
  EXPECT_NE(decode_log(frames(kMoveOfTheMosiEndChip), 3, o).find("Move(FWD"), std::string::npos);
  o.only_chip = 2;  // the MISO end: it only got NOPs
  EXPECT_EQ(decode_log(frames(kMoveOfTheMosiEndChip), 3, o).find("Move(FWD"), std::string::npos);
  o.only_chip = 3;
  EXPECT_THROW(decode_log(frames(kMoveOfTheMosiEndChip), 3, o), std::invalid_argument);
}

TEST(ChipNumberingInDecode, NamesTheChipsOfAShortFrameAsTheUserCountsThem) {
  DecodeOptions o;
  o.number_from = NumberFrom::mosi;
  // Two bytes for three chips: the MISO-end chip decodes a byte left in the chain.
  const std::string log = decode_log(frames({"D0 D0 | 00 00"}), 3, o);
  EXPECT_NE(log.find("2 bytes for a chain of 3: chip 2 decodes a byte left in the chain, not host bytes (chip 2 decodes"),
            std::string::npos)
      << log;
}

TEST(ChipNumberingInReplay, ReportsTheMosiEndChipAsChipZero) {
  // GetStatus to the chip nearest MOSI; the capture says its UVLO flag was already cleared.
  const std::string text = frames({"00 00 D0 | 00 00 00", "00 00 00 | 00 00 7E"});
  NativeTraceReader r(text, "t.trace");
  Chain chain(3);
  ReplayOptions o;
  o.number_from = NumberFrom::mosi;
  const ReplayResult res = replay_trace(r, chain, o);
  ASSERT_EQ(res.divergences.size(), 1u);
  const std::string& rep = res.divergences[0].report;
  EXPECT_NE(rep.find("MISO byte 2 expected 0x7E, emulated 0x7C"), std::string::npos) << rep;
  EXPECT_NE(rep.find("byte 2: chip 0: byte 1 of 2 of the GetStatus answer"), std::string::npos) << rep;
  // The chips in the user's order, chip 0 first.
  EXPECT_NE(rep.find("    chip 0: decodes 0x00 = NOP\n    chip 1: decodes 0x00 = NOP\n    chip 2: decodes 0x00 = NOP\n"),
            std::string::npos)
      << rep;
  EXPECT_NE(rep.find("  chip 0 state (emulated, as it answered):"), std::string::npos) << rep;
}

TEST(ChipNumberingInMotionSeries, SamplesTheChipTheUserNamed) {
  Chain chain(3);
  Trace trace;
  RecordingChain rec(chain, trace);
  ChainHost host(chain, rec);
  host.move(2, true, 3200);  // the chain's chip 2: the MOSI end
  host.wait_ms(600);
  host.get_status(2);
  MotionOptions o;
  o.number_from = NumberFrom::mosi;
  o.chips = {0};
  Chain fresh = make_chain(parse_chain_spec(trace.header.chain));
  auto pass = trace.reader();
  const Tick end = trace_end_tick(*pass);
  auto reader = trace.reader();
  const MotionSeries m = sample_motion(*reader, fresh, end, o);
  ASSERT_EQ(m.chips.size(), 1u);
  EXPECT_EQ(m.chips[0].chip, 2u);
  EXPECT_EQ(m.chips[0].number, 0u);
  EXPECT_EQ(m.chips[0].samples.back().abs_pos, 3200);
}

}  // namespace
}  // namespace l6470emu
