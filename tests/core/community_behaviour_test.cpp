// Behaviours that users reported on forums and in GitHub issues (spec §9 and §10),
// restricted to those that apply to the L6470. Each test names its source item.
// Not covered: host-side bit-level SPI bugs (§9.5/§10.4/§10.5 causes) that a
// byte-level model cannot reproduce — only the correct chip side of them.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "core/chip.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;


constexpr std::uint32_t kConfigReset = 0x2E88;
constexpr std::uint32_t kSwMode = 1u << 4;

struct Rig : test::OneChip {
  ChainHost& h() { return host; }
  std::uint16_t status() { return static_cast<std::uint16_t>(host.get_param(0, Reg::STATUS)); }
  std::uint16_t get_status() { return host.get_status(0); }
  std::int32_t abs_pos() { return sign_extend(host.get_param(0, Reg::ABS_POS), 22); }
  bool busy() { return !chip().busy_sync_pin(); }
  void wait_s(double s) { host.wait(static_cast<Tick>(s * kTicksPerSecond)); }
  void wait_until_idle(double limit_s = 3.0) {
    const Tick limit = chain.now() + static_cast<Tick>(limit_s * kTicksPerSecond);
    while (busy() && chain.now() < limit) chain.advance_to(chain.now() + 64);
  }
  void power_up_with_switch_closed() {
    chip().set_stby_rst_pin(false);
    host.wait(ticks_from_us(20));
    chip().set_sw_pin(false);
    chip().set_stby_rst_pin(true);
    host.wait(ticks_from_us(50));
  }
};

// ---- §9 forum threads ------------------------------------------------------------------

// §9 item 1: SW low at power-up -> the chip leaves HiZ, and INT_SPEED / ST_SLP /
// FN_SLP_ACC / FN_SLP_DEC (WH) can no longer be written.
TEST(CommunityBehaviour, SwitchLowAtPowerUpLocksTheBackEmfRegisters) {
  Rig r;
  r.power_up_with_switch_closed();
  auto s = r.get_status();
  EXPECT_FALSE(s & kHiZ);
  EXPECT_TRUE(s & kSwEvn);
  struct W { Reg reg; std::uint32_t reset, value; };
  for (const W& w : {W{Reg::INT_SPEED, 0x0408, 0x0123}, W{Reg::ST_SLP, 0x19, 0x33},
                     W{Reg::FN_SLP_ACC, 0x29, 0x44}, W{Reg::FN_SLP_DEC, 0x29, 0x55}}) {
    r.h().set_param(0, w.reg, w.value);
    EXPECT_TRUE(r.get_status() & kNotPerf);
    EXPECT_EQ(r.h().get_param(0, w.reg), w.reset);
  }
  r.h().hard_hiz(0);  // the way out
  r.h().set_param(0, Reg::INT_SPEED, 0x0123);
  EXPECT_FALSE(r.get_status() & kNotPerf);
  EXPECT_EQ(r.h().get_param(0, Reg::INT_SPEED), 0x0123u);
}

// §9 item 2: STEP_MODE written while stopped but with the bridges enabled -> NOTPERF, 0x7E8x.
TEST(CommunityBehaviour, StepModeWriteWhileStoppedButEnabledIsNotPerformable) {
  Rig r;
  EXPECT_EQ(r.get_status(), 0x7C03);
  r.h().hard_stop(0);  // enabled, not moving
  r.h().set_param(0, Reg::STEP_MODE, 0x80 | 0x03);  // the thread tried to switch to SYNC mode
  const auto s = r.get_status();
  EXPECT_EQ(s & 0xFFF0, 0x7E80);
  EXPECT_EQ(s, 0x7E82);
  EXPECT_EQ(r.h().get_param(0, Reg::STEP_MODE), 0x07u);
  r.h().hard_hiz(0);
  r.h().set_param(0, Reg::STEP_MODE, 0x80 | 0x03);
  EXPECT_FALSE(r.get_status() & kNotPerf);
  EXPECT_EQ(r.h().get_param(0, Reg::STEP_MODE), 0x83u);
}

// §9 item 3 is about the powerSTEP01; the L6470 takes ResetDevice at any time (docs/chip-model.md).
TEST(CommunityBehaviour, ResetDeviceIsAcceptedWithTheBridgesEnabledOnTheL6470) {
  Rig r;
  r.h().set_param(0, Reg::ACC, 0x100);
  r.h().hard_stop(0);
  r.get_status();
  r.h().reset_device(0);
  EXPECT_EQ(r.get_status(), 0x7C03);
  EXPECT_EQ(r.h().get_param(0, Reg::ACC), 0x08Au);
}

// §9 item 4: with CS held low the chip is a plain shift register: the byte comes back
// on the next transfer and only the last byte before CS rises is decoded.
TEST(CommunityBehaviour, CsHeldLowEchoesTheByteAndDecodesOnlyTheLastOne) {
  Rig r;
  r.get_status();
  const std::vector<std::uint8_t> tx = {0x25, 0x00};  // GetParam(ACC), NOP, one CS-low period
  const auto rx = r.chain.frame(tx);
  ASSERT_EQ(rx.size(), 2u);
  EXPECT_EQ(rx[0], 0x00);
  EXPECT_EQ(rx[1], 0x25) << "the first byte is echoed";
  const std::uint8_t nop[] = {0x00};
  EXPECT_EQ(r.h().send(0, nop)[0], 0x00) << "GetParam was never decoded: no answer";
  EXPECT_EQ(r.get_status(), 0x7E03) << "nothing went wrong either";
}

// §9 item 5 and §10 #5: values with bit 7 set (ABS_POS 128..200) read back whole.
TEST(CommunityBehaviour, AbsPosValuesWithBit7SetReadBackWhole) {
  Rig r;
  r.h().step_clock(0, true);
  for (std::int32_t expected = 1; expected <= 200; ++expected) {
    r.chip().set_stck_pin(true);
    r.h().wait(4);
    r.chip().set_stck_pin(false);
    if (expected >= 120) {
      ASSERT_EQ(r.h().get_param(0, Reg::ABS_POS), static_cast<std::uint32_t>(expected));
    }
  }
  EXPECT_EQ(r.h().get_param(0, Reg::EL_POS), 200u % 512u);
  r.h().set_param(0, Reg::ABS_POS, 0x808080);  // 0x008080 after the 22-bit mask
  EXPECT_EQ(r.h().get_param(0, Reg::ABS_POS), 0x008080u);
}

// §9 item 6 (L6480 CONFIG read as 0x2C08): on the L6470 CONFIG resets to 0x2E88, bit 7 (OC_SD) set.
TEST(CommunityBehaviour, ConfigReadsItsResetValueWithBit7Set) {
  Rig r;
  EXPECT_EQ(r.h().get_param(0, Reg::CONFIG), 0x2E88u);
}

// §9 item 7: GetParam followed at once by Run (no NOPs to collect the answer): the
// answer comes out during the Run bytes and the Run is executed all the same.
TEST(CommunityBehaviour, GetParamFollowedAtOnceByRunAnswersAndRuns) {
  Rig r;
  r.get_status();
  const std::uint8_t bytes[] = {0x39, 0x51, 0x00, 0x20, 0x00};  // GetParam(STATUS), Run(FWD, 0x2000)
  const auto miso = r.h().send(0, bytes);
  EXPECT_EQ(miso[0], 0x00);
  EXPECT_EQ(miso[1], 0x7E);
  EXPECT_EQ(miso[2], 0x03);
  EXPECT_EQ(miso[3], 0x00);
  EXPECT_EQ(miso[4], 0x00);
  r.wait_s(0.2);
  EXPECT_GT(r.abs_pos(), 0);
  EXPECT_EQ(r.h().get_param(0, Reg::SPEED), 0x2000u);
  EXPECT_FALSE(r.get_status() & (kNotPerf | kWrongCmd));
}

// §9 item 8: a Move sent as four bytes in one CS-low period decodes only the last byte.
TEST(CommunityBehaviour, MoveSentInOneChipSelectPeriodDoesNotMove) {
  Rig r;
  r.get_status();
  const std::vector<std::uint8_t> move = {0x41, 0x00, 0x10, 0x00};
  r.chain.frame(move);
  r.wait_s(0.1);
  EXPECT_EQ(r.abs_pos(), 0);
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.get_status(), 0x7E03);
  // The same bytes one CS frame each do move.
  r.h().send(0, move);
  r.wait_until_idle();
  EXPECT_EQ(r.abs_pos(), 0x1000);
}

// ---- §10 GitHub issues --------------------------------------------------------------------

// §10 #1: with SW_MODE = 0 every later switch closure hard-stops the motor, not only
// during GoUntil; setting SW_MODE = 1 (CONFIG is WH: in HiZ) ends that.
TEST(CommunityBehaviour, SwMode0HardStopsOnEveryLaterSwitchClosure) {
  Rig r;
  r.h().set_param(0, Reg::ACC, 0x400);
  r.h().set_param(0, Reg::DEC, 0x400);
  // Homing.
  r.h().go_until(0, false, false, test::spd_from_steps_per_s(400));
  r.wait_s(0.1);
  r.chip().set_sw_pin(false);
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.abs_pos(), 0);
  r.h().release_sw(0, false, true);
  r.wait_s(0.05);
  r.chip().set_sw_pin(true);
  ASSERT_FALSE(r.busy());
  ASSERT_EQ(r.abs_pos(), 0);
  // Later moves: each closure stops the motor.
  for (int i = 0; i < 3; ++i) {
    r.h().move(0, true, 100000);
    r.wait_s(0.1);
    ASSERT_TRUE(r.busy());
    r.chip().set_sw_pin(false);
    EXPECT_FALSE(r.busy()) << "closure " << i;
    const std::int32_t p = r.abs_pos();
    r.wait_s(0.05);
    EXPECT_EQ(r.abs_pos(), p);
    EXPECT_LT(p, 100000 * (i + 1));
    r.chip().set_sw_pin(true);
    r.h().go_to(0, 0);
    r.wait_until_idle();
  }
  // The library fix: SW_MODE = 1, which needs the bridges in HiZ.
  r.get_status();
  r.h().set_param(0, Reg::CONFIG, kConfigReset | kSwMode);
  EXPECT_TRUE(r.get_status() & kNotPerf) << "CONFIG is WH";
  r.h().hard_hiz(0);
  r.h().set_param(0, Reg::CONFIG, kConfigReset | kSwMode);
  EXPECT_FALSE(r.get_status() & kNotPerf);
  r.h().move(0, true, 20000);
  r.wait_s(0.05);
  r.chip().set_sw_pin(false);
  EXPECT_TRUE(r.busy());
  r.wait_until_idle();
  EXPECT_EQ(r.abs_pos(), 20000);
  EXPECT_TRUE(r.status() & (kSwEvn | kSwF));
}

// §10 #3: a STATUS read while STBY\RST is still low returns 0.
TEST(CommunityBehaviour, StatusReadBeforeReleasingResetReadsZero) {
  Rig r;
  r.chip().set_stby_rst_pin(false);
  EXPECT_EQ(r.get_status(), 0x0000);
  r.chip().set_stby_rst_pin(true);
  r.h().wait(ticks_from_us(50));
  EXPECT_EQ(r.get_status(), 0x7C03);
}

// §10 #4: a daisy-chained GetStatus of three chips reads the same word from each
// (the reported 7E03 FE03 FE03 came from a host bug; bit 15, SCK_MOD, is 0).
TEST(CommunityBehaviour, ThreeChipChainGetStatusReadsTheSameWordFromEveryChip) {
  Chain chain(3);
  ChainHost host(chain);
  const std::vector<std::vector<std::uint8_t>> get_status(3, std::vector<std::uint8_t>{0xD0, 0x00, 0x00});
  auto frames = host.send_all(get_status);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(frames[1][k], 0x7C);
    EXPECT_EQ(frames[2][k], 0x03);
  }
  frames = host.send_all(get_status);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(frames[1][k], 0x7E) << "chip " << k;
    EXPECT_EQ(frames[2][k], 0x03) << "chip " << k;
  }
}

// §10 #6: two back-to-back ABS_POS reads while running differ, each being a snapshot
// taken when its GetParam opcode is decoded.
TEST(CommunityBehaviour, BackToBackAbsPosReadsWhileRunningAreSnapshotsAtTheirDecode) {
  Rig r;
  r.h().set_param(0, Reg::ACC, 0xFFF);
  r.h().set_param(0, Reg::MAX_SPEED, 0x3FF);
  r.h().run(0, true, test::spd_from_steps_per_s(15000));
  r.wait_s(0.01);
  // The host sends one frame per byte, 8 ticks apart: read 1 is decoded 8 ticks from
  // now, read 2 four frames (32 ticks) later.
  const Tick now = r.chain.now();
  Chip probe = r.chip();
  probe.advance_to(now + 8);
  const std::uint32_t at_first = probe.peek(Reg::ABS_POS);
  probe.advance_to(now + 8 + 32);
  const std::uint32_t at_second = probe.peek(Reg::ABS_POS);
  const std::uint32_t first = r.h().get_param(0, Reg::ABS_POS);
  const std::uint32_t second = r.h().get_param(0, Reg::ABS_POS);
  EXPECT_EQ(first, at_first);
  EXPECT_EQ(second, at_second);
  EXPECT_NE(first, second);
  EXPECT_NEAR(static_cast<double>(second - first), 32 * 15000.0 * 128 / 4e6, 1.0);
}

// §10 #7: GoTo 33000 reads back as 33000 (22-bit two's complement, not 16-bit).
TEST(CommunityBehaviour, PositionsBeyondSixteenBitsKeepTheir22BitValue) {
  Rig r;
  r.h().set_param(0, Reg::ACC, 0xFFF);
  r.h().set_param(0, Reg::MAX_SPEED, 0x3FF);
  r.h().go_to(0, 33000);
  r.wait_until_idle();
  EXPECT_EQ(r.h().get_param(0, Reg::ABS_POS), 33000u);  // 0x0080E8
  EXPECT_EQ(r.abs_pos(), 33000);
  r.h().go_to(0, -32766);
  r.wait_until_idle();
  EXPECT_EQ(r.h().get_param(0, Reg::ABS_POS), 0x3F8002u);
  EXPECT_EQ(r.abs_pos(), -32766);
  r.h().set_param(0, Reg::MARK, 0x3F8002);
  EXPECT_EQ(sign_extend(r.h().get_param(0, Reg::MARK), 22), -32766);
}

TEST(CommunityBehaviour, AbsPosRollsFromPlusToMinusTwoToThe21) {
  Rig r;
  r.h().set_param(0, Reg::ABS_POS, 0x1FFFFF);  // 2^21 - 1
  EXPECT_EQ(r.abs_pos(), (1 << 21) - 1);
  r.h().move(0, true, 1);
  r.wait_until_idle();
  EXPECT_EQ(r.h().get_param(0, Reg::ABS_POS), 0x200000u);
  EXPECT_EQ(r.abs_pos(), -(1 << 21));
  r.h().move(0, false, 1);
  r.wait_until_idle();
  EXPECT_EQ(r.h().get_param(0, Reg::ABS_POS), 0x1FFFFFu);
}

TEST(CommunityBehaviour, GoToIgnoresTheTopTwoBitsOfItsArgument) {
  Rig r;
  r.h().set_param(0, Reg::ACC, 0xFFF);
  r.h().set_param(0, Reg::MAX_SPEED, 0x3FF);
  const std::uint8_t go_to[] = {0x60, 0xC0, 0x80, 0xE8};  // 0xC080E8: 33000 with bits 23:22 set
  r.h().send(0, go_to);
  r.wait_until_idle();
  EXPECT_EQ(r.abs_pos(), 33000);
  EXPECT_FALSE(r.get_status() & (kWrongCmd | kNotPerf));
}

// §10 #8: MOT_STATUS is bits 6:5 (a library read it 13 bits higher, where the
// active-low STEP_LOSS flags sit and read 11 when nothing stalls).
TEST(CommunityBehaviour, MotStatusSitsInBits6And5) {
  Rig r;
  r.get_status();
  EXPECT_EQ(r.status() & 0x60, 0x00);
  r.h().move(0, true, 1000u << 7);  // reset profile: 1.5 s
  r.wait_s(0.2);
  std::uint16_t s = r.status();
  EXPECT_EQ(s & 0x60, 0x20) << "acceleration";
  EXPECT_EQ(s & 0x6000, 0x6000);
  r.wait_s(0.55);
  s = r.status();
  EXPECT_EQ(s & 0x60, 0x60) << "constant speed";
  EXPECT_EQ(s & 0x6000, 0x6000);
  r.wait_s(0.55);
  s = r.status();
  EXPECT_EQ(s & 0x60, 0x40) << "deceleration";
  EXPECT_EQ(s & 0x6000, 0x6000);
  r.wait_s(0.3);
  s = r.status();
  EXPECT_EQ(s & 0x60, 0x00) << "stopped";
  EXPECT_TRUE(s & kBusyN);
  EXPECT_FALSE(s & kSwF);
}

}  // namespace
}  // namespace l6470emu
