// SPI framing of one chip (spec §1, datasheet §8 and §9.2.1, Figs. 19-21; docs/chip-model.md
// "SPI framing"): an 8-bit shift register decoded at the CS rising edge, answers in the
// following bytes MSB first, answers aborted and replaced, CS held low, empty CS pulses.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "daisychain/chain.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;

using Bytes = std::vector<std::uint8_t>;


/// One L6470 behind its own chip-select.
struct Single {
  Chain chain{1};
  Chip& chip() { return chain.chip(0); }
  /// Each byte in a CS frame of its own (how the chip must be driven).
  Bytes per_byte(const Bytes& tx) {
    Bytes rx;
    for (auto b : tx) rx.push_back(chain.frame(Bytes{b})[0]);
    return rx;
  }
  /// All bytes in one CS frame (CS held low).
  Bytes held(const Bytes& tx) { return chain.frame(tx); }
};

/// A chip with ABS_POS = 0x123456 and INT_SPEED = 0x0ABC, no answer pending.
struct Loaded : Single {
  Loaded() {
    per_byte({0x01, 0x12, 0x34, 0x56});  // SetParam(ABS_POS)
    per_byte({0x0D, 0x0A, 0xBC});        // SetParam(INT_SPEED), WH: fine in HiZ
  }
};

TEST(Framing, CommandByteItselfReturnsZero) {
  for (std::uint8_t op : {0xD0, 0x21, 0x39, 0x51, 0x00, 0xEB}) {
    Single s;
    EXPECT_EQ(s.per_byte({op}), Bytes{0x00}) << int(op);
  }
}

TEST(Framing, WithNoAnswerPendingEveryByteReturnsZero) {
  Single s;
  EXPECT_EQ(s.per_byte({0x00, 0x0A, 0x30, 0xB8, 0x00, 0x00}), Bytes(6, 0x00));
}

TEST(Framing, GetParamAnswerComesInTheFollowingBytesMsbFirst) {
  Loaded s;
  EXPECT_EQ(s.per_byte({0x21, 0x00, 0x00, 0x00, 0x00}), (Bytes{0x00, 0x12, 0x34, 0x56, 0x00}));
  EXPECT_EQ(s.per_byte({0x38, 0x00, 0x00, 0x00}), (Bytes{0x00, 0x2E, 0x88, 0x00}));  // CONFIG, 2 bytes
  EXPECT_EQ(s.per_byte({0x29, 0x00, 0x00}), (Bytes{0x00, 0x29, 0x00}));              // KVAL_HOLD, 1 byte
}

TEST(Framing, GetStatusAnswerComesInTheTwoFollowingBytesMsbFirst) {
  Single s;
  EXPECT_EQ(s.per_byte({0xD0, 0x00, 0x00, 0x00}), (Bytes{0x00, 0x7C, 0x03, 0x00}));
}

TEST(Framing, ANewAnswerAbortsTheOneBeingShiftedOutAsInDatasheetFigure21) {
  // cmd1 3-byte answer, cmd2 none, cmd3 2-byte answer, cmd4 and cmd5 none.
  Loaded s;
  const Bytes tx{0x21 /*GetParam ABS_POS*/, 0xD8 /*ResetPos*/, 0x2D /*GetParam INT_SPEED*/, 0x00, 0x00, 0x00};
  const Bytes want{0x00, 0x12 /*cmd1 MSB*/, 0x34 /*cmd1 middle*/, 0x0A /*cmd3 MSB*/, 0xBC /*cmd3 LSB*/, 0x00};
  EXPECT_EQ(s.per_byte(tx), want);
  EXPECT_EQ(s.chip().peek(Reg::ABS_POS), 0u) << "cmd2 was executed";
}

TEST(Framing, GetStatusAbortsAPendingGetParamAnswer) {
  Loaded s;
  EXPECT_EQ(s.per_byte({0x21, 0xD0, 0x00, 0x00, 0x00}), (Bytes{0x00, 0x12, 0x7C, 0x03, 0x00}));
}

TEST(Framing, RepeatingAGetParamRestartsItsAnswer) {
  Loaded s;
  EXPECT_EQ(s.per_byte({0x21, 0x21, 0x00, 0x00, 0x00}), (Bytes{0x00, 0x12, 0x12, 0x34, 0x56}));
}

TEST(Framing, ArgumentBytesClockOutAPendingAnswer) {
  Loaded s;
  EXPECT_EQ(s.per_byte({0x21, 0x0A, 0x77, 0x00}), (Bytes{0x00, 0x12, 0x34, 0x56}));
  EXPECT_EQ(s.chip().peek(Reg::KVAL_RUN), 0x77u) << "SetParam was executed meanwhile";
  EXPECT_EQ(s.per_byte({0x21, 0x51, 0x00, 0x10, 0x00}), (Bytes{0x00, 0x12, 0x34, 0x56, 0x00}));
  EXPECT_NE(s.chip().status() & 0x0060, 0) << "Run was executed meanwhile";
}

TEST(Framing, AWrongCommandByteAlsoClocksOutAPendingAnswer) {
  Loaded s;
  EXPECT_EQ(s.per_byte({0x21, 0xEB, 0xF8, 0x00}), (Bytes{0x00, 0x12, 0x34, 0x56}));
  EXPECT_NE(s.chip().status() & kWrongCmd, 0);
}

TEST(Framing, ArgumentBytesThatLookLikeCommandsAreOnlyValues) {
  Single s;
  // SetParam(MARK, 0x21D039): the value bytes are GetParam/GetStatus opcodes, but only values.
  EXPECT_EQ(s.per_byte({0x03, 0x21, 0xD0, 0x39, 0x00, 0x00}), Bytes(6, 0x00));
  EXPECT_EQ(s.chip().peek(Reg::MARK), 0x21D039u);
}

TEST(Framing, ResponseIsASnapshotTakenWhenTheOpcodeIsDecoded) {
  Loaded s;
  EXPECT_EQ(s.per_byte({0x21, 0x01, 0x00, 0x00, 0x07, 0x00}), (Bytes{0x00, 0x12, 0x34, 0x56, 0x00, 0x00}));
  EXPECT_EQ(s.chip().peek(Reg::ABS_POS), 7u);
}

// ---------------------------------------------------------------- CS held low

TEST(Framing, WithCsHeldLowOnlyTheLastByteIsDecoded) {
  Loaded s;
  // 0x29 (GetParam KVAL_HOLD) passes through; 0xD8 (ResetPos) is decoded.
  EXPECT_EQ(s.held({0x29, 0xD8}), (Bytes{0x00, 0x29}));
  EXPECT_EQ(s.chip().peek(Reg::ABS_POS), 0u);
  EXPECT_EQ(s.per_byte({0x00}), Bytes{0x00}) << "no KVAL_HOLD answer: 0x29 was never decoded";
}

TEST(Framing, WithCsHeldLowASingleChipEchoesTheEarlierBytesBack) {
  // Spec §9 item 4 (ST answer: keep CS low and the device echoes the byte back on the next transfer).
  Single s;
  EXPECT_EQ(s.held({0xAB, 0xCD, 0xEF, 0x00}), (Bytes{0x00, 0xAB, 0xCD, 0xEF}));
  EXPECT_EQ(s.chip().status() & kWrongCmd, 0) << "only the last byte (NOP) was decoded";
  s.held({0x00, 0xEB});
  EXPECT_NE(s.chip().status() & kWrongCmd, 0) << "the last byte is decoded";
}

TEST(Framing, WithCsHeldLowAMultiByteCommandIsNotAssembled) {
  // Spec §9 item 8: SetParam(KVAL_RUN, 0x55) in one CS frame decodes only 0x55, an unknown opcode.
  Single s;
  s.held({0x0A, 0x55});
  EXPECT_EQ(s.chip().peek(Reg::KVAL_RUN), 0x29u);
  EXPECT_NE(s.chip().status() & kWrongCmd, 0);
}

TEST(Framing, AHeldFrameConsumesOnlyOneAnswerByte) {
  Single s;
  s.per_byte({0xD0});
  EXPECT_EQ(s.held({0x00, 0x00}), (Bytes{0x7C, 0x00}));  // answer MSB, then the echo of our NOP
  EXPECT_EQ(s.per_byte({0x00, 0x00}), (Bytes{0x03, 0x00}));
}

// ---------------------------------------------------------------- empty pulses and CS high

TEST(Framing, ACsPulseWithoutBytesDecodesNothing) {
  Loaded s;
  s.per_byte({0x21});  // 0x12 now waits in the shift register
  s.chain.select();
  EXPECT_EQ(s.chain.bytes_in_frame(), 0u);
  s.chain.deselect();
  // Had 0x12 been decoded it would be SetParam(OCD_TH) and swallow the next byte.
  EXPECT_EQ(s.per_byte({0x00, 0x00, 0x00, 0x00}), (Bytes{0x12, 0x34, 0x56, 0x00}));
  EXPECT_EQ(s.chip().peek(Reg::OCD_TH), 0x8u);
  EXPECT_EQ(s.chip().status() & kWrongCmd, 0);
}

TEST(Framing, ACsPulseWithoutBytesLeavesAFreshChipAsItIs) {
  Single s;
  for (int i = 0; i < 5; ++i) {
    s.chain.select();
    s.chain.deselect();
  }
  EXPECT_EQ(s.chip().status(), 0x7C03);
  EXPECT_EQ(s.per_byte({0xD0, 0x00, 0x00}), (Bytes{0x00, 0x7C, 0x03}));
}

TEST(Framing, ExchangeWhileCsIsHighReturnsZeroAndIsIgnored) {
  Single s;
  s.per_byte({0xD0});  // 0x7C waits in the shift register
  ASSERT_FALSE(s.chain.selected());
  EXPECT_EQ(s.chain.exchange(std::uint8_t{0xEB}), 0x00);
  EXPECT_EQ(s.chain.exchange(std::uint8_t{0x00}), 0x00);
  s.chain.deselect();  // no CS falling edge happened: nothing to decode
  EXPECT_EQ(s.chip().status() & kWrongCmd, 0);
  EXPECT_EQ(s.per_byte({0x00, 0x00}), (Bytes{0x7C, 0x03}));
}

TEST(Framing, SelectedReportsTheChipSelectLevel) {
  Single s;
  EXPECT_FALSE(s.chain.selected());
  s.chain.select();
  EXPECT_TRUE(s.chain.selected());
  s.chain.exchange(std::uint8_t{0x00});
  s.chain.exchange(std::uint8_t{0x00});
  EXPECT_EQ(s.chain.bytes_in_frame(), 2u);
  s.chain.deselect();
  EXPECT_FALSE(s.chain.selected());
}

TEST(Framing, ASecondSelectWhileSelectedDoesNotStartANewFrame) {
  Single s;
  s.chain.select();
  s.chain.exchange(std::uint8_t{0xEB});
  s.chain.select();  // CS is already low: no edge
  s.chain.deselect();
  EXPECT_NE(s.chip().status() & kWrongCmd, 0) << "0xEB is still in the register at the CS rise";
}

}  // namespace
}  // namespace l6470emu
