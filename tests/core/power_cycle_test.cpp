// A brown-out (Chip::power_cycle, the `reset` fault): the chip comes back as at power-up,
// whatever it was doing; its pins, the physical conditions and its axis's rotor stay.
// Not the chain's shift register (tests/daisychain/wire_faults_test.cpp).
#include <gtest/gtest.h>

#include <cstdint>

#include "core/chip.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;

struct Rig : test::OneChip {
  Rig() { host.get_status(0); }  // past the power-up UVLO flag
};

TEST(PowerCycle, PutsEveryRegisterBackToItsResetValue) {
  Rig r;
  r.host.set_param(0, Reg::KVAL_RUN, 0x55);
  r.host.set_param(0, Reg::MAX_SPEED, 0x10);
  r.host.set_param(0, Reg::MARK, 1234);
  r.host.run(0, true, test::spd_from_steps_per_s(400));
  r.host.wait_ms(300);
  ASSERT_NE(r.chip().position(), 0);
  r.chip().power_cycle();
  const Chip fresh;  // a chip just out of power-up
  for (const RegisterInfo& reg : r.chip().registers().registers) {
    if (reg.id == Reg::STATUS) continue;  // compared below, with the latched flags
    EXPECT_EQ(r.chip().peek_address(reg.address), fresh.peek_address(reg.address)) << reg.name;
  }
  EXPECT_EQ(r.chip().position(), 0) << "ABS_POS is lost";
  EXPECT_EQ(r.chip().motion().speed, 0u);
}

TEST(PowerCycle, LatchesUvloAndLeavesTheBridgesInHiZWithFlagLow) {
  Rig r;
  r.host.run(0, true, test::spd_from_steps_per_s(400));
  r.host.wait_ms(100);
  ASSERT_FALSE(r.chip().hiz());
  ASSERT_TRUE(r.chip().flag_pin());
  r.chip().power_cycle();
  EXPECT_TRUE(r.chip().hiz());
  EXPECT_FALSE(r.chip().flag_pin()) << "the power-up UVLO pulls FLAG low";
  EXPECT_TRUE(r.chip().busy_sync_pin()) << "no motion";
  const std::uint16_t s = r.chip().status();
  EXPECT_EQ(s & kUvloN, 0) << "UVLO latched";
  EXPECT_NE(s & kHiZ, 0);
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_EQ(s, Chip().status()) << "STATUS as just after power-up";
  // GetStatus clears the UVLO latch as after a real power-up.
  r.host.get_status(0);
  EXPECT_NE(r.chip().status() & kUvloN, 0);
}

TEST(PowerCycle, DropsACommandBeingCollected) {
  Rig r;
  const std::uint8_t set_kval_run[] = {0x0A};
  r.host.send(0, set_kval_run);  // SetParam(KVAL_RUN): waits for its value byte
  ASSERT_TRUE(r.chip().collecting_arguments());
  r.chip().power_cycle();
  EXPECT_FALSE(r.chip().collecting_arguments());
  const std::uint8_t value[] = {0x77};
  r.host.send(0, value);  // now an opcode of its own (0x77: no such command), not KVAL_RUN's value
  EXPECT_EQ(r.chip().peek(Reg::KVAL_RUN), Chip().peek(Reg::KVAL_RUN));
}

TEST(PowerCycle, KeepsTheInputPinsAndTheConditionsOfThePhysicalWorld) {
  Rig r;
  r.chip().set_sw_pin(false);
  r.chip().set_overcurrent(true);
  r.chip().power_cycle();
  EXPECT_FALSE(r.chip().sw_pin());
  EXPECT_EQ(r.chip().status() & kOcdN, 0) << "an overcurrent still going on shows at once";
}

TEST(PowerCycle, TheAxisKeepsItsRotorWithTheBridgesOff) {
  Rig r;
  r.chip().attach_axis(AxisSpec{});
  r.host.run(0, true, test::spd_from_steps_per_s(200));
  r.host.wait_ms(500);
  const Axis* before = r.chip().axis();
  ASSERT_NE(before, nullptr);
  const std::int64_t rotor = before->true_position();
  ASSERT_NE(rotor, 0);
  r.chip().power_cycle();
  const Axis* after = r.chip().axis();
  ASSERT_NE(after, nullptr) << "the axis is still there";
  EXPECT_NEAR(static_cast<double>(after->true_position()), static_cast<double>(rotor), 128.0 * 4);
  EXPECT_EQ(r.chip().position(), 0);
  r.host.wait_ms(200);
  EXPECT_TRUE(r.chip().hiz());
}

TEST(PowerCycle, InStandbyTheLogicStaysInReset) {
  Rig r;
  r.chip().set_stby_rst_pin(false);
  r.chip().power_cycle();
  EXPECT_FALSE(r.chip().spi_enabled());
  r.chip().set_stby_rst_pin(true);
  EXPECT_TRUE(r.chip().spi_enabled());
  EXPECT_EQ(r.chip().status() & kUvloN, 0);
}

}  // namespace
}  // namespace l6470emu
