// GoogleTest tests of emulated daisy chains in virtual time: the shape of a driver's unit tests
// (docs/guide/cpp.md). Chain is N chips behind one chip-select, ChainHost the reference host.
#include <gtest/gtest.h>

#include <cstdint>
#include <l6470emu/core/axis_text.hpp>
#include <l6470emu/daisychain/chain.hpp>
#include <l6470emu/daisychain/host.hpp>
#include <vector>

using namespace l6470emu;

TEST(Chain, ThreeChipsMoveIndependently) {
  Chain chain(3);                        // three L6470s behind one chip-select
  ChainHost host(chain);                 // one CS frame per byte, NOP to the other chips
  EXPECT_EQ(host.get_status(2), 0x7C03); // power-up: HiZ, UVLO latched
  host.move(2, /*forward=*/true, 3200);  // chip 2: 3200 microsteps (25 full steps at 1/128)
  EXPECT_FALSE(chain.chip(2).busy_sync_pin());       // BUSY pin pulled low
  host.wait_ms(500);                     // half a second of virtual time
  EXPECT_EQ(host.get_param(2, Reg::ABS_POS), 3200u);
  EXPECT_TRUE(chain.chip(2).busy_sync_pin());
  EXPECT_EQ(host.get_param(0, Reg::ABS_POS), 0u);    // the others never moved

  // The same GetStatus at byte level: 3-byte frames, byte k is chip k's.
  chain.frame(std::vector<std::uint8_t>{0xD0, 0xD0, 0xD0});
  auto msb = chain.frame(std::vector<std::uint8_t>{0x00, 0x00, 0x00});
  EXPECT_EQ(msb, (std::vector<std::uint8_t>{0x7C, 0x7C, 0x7E}));  // only chip 2 had UVLO cleared
}

TEST(Chain, AnL6480BesideAnL6470) {
  Chain chain(std::vector<Chip>{Chip(l6470()), Chip(l6480())});  // chip 0 (the MISO end) first
  ChainHost host(chain);
  EXPECT_EQ(host.get_param(0, Reg::CONFIG), 0x2E88u);  // at 0x18 on the L6470
  EXPECT_EQ(host.get_param(1, Reg::CONFIG), 0x2C88u);  // at 0x1A on the L6480
  host.move(1, Direction::reverse, 6400);
  EXPECT_TRUE(host.status(1).busy());
  EXPECT_TRUE(host.wait_until_idle_ms(1, 2000));       // virtual time runs to BUSY's rise
  EXPECT_EQ(host.get_param(1, Reg::ABS_POS), 0x400000u - 6400);  // 22-bit two's complement
}

TEST(Chain, AnOvercurrentReachesFlagAndStatus) {
  Chain chain(1);
  ChainHost host(chain);
  host.get_status(0);                   // clears the UVLO latched at power-up: FLAG rises
  EXPECT_TRUE(chain.chip(0).flag_pin());
  chain.chip(0).set_overcurrent(true);  // the physical world, beside SPI
  EXPECT_FALSE(chain.chip(0).flag_pin());
  chain.advance_to(chain.now() + ticks_from_ms(10));  // time moves only when told
  chain.chip(0).set_overcurrent(false);
  EXPECT_FALSE(chain.chip(0).flag_pin());     // OCD is latched ...
  EXPECT_TRUE(host.status(0).overcurrent());  // ... until GetStatus reads it
  EXPECT_TRUE(chain.chip(0).flag_pin());
}

TEST(Chain, AMotorAgainstAHardStopLosesSteps) {
  Chain chain(1);
  ChainHost host(chain);
  AxisSpec axis;  // a NEMA-17 behind the chip; the items are those of the board's axis.K=
  ASSERT_EQ(parse_axis_spec("stops=..1280", axis), "");  // a hard stop 10 full steps ahead
  chain.chip(0).attach_axis(axis);
  host.move(0, Direction::forward, 6400);
  ASSERT_TRUE(host.wait_until_idle_ms(0, 2000));
  EXPECT_EQ(host.get_param(0, Reg::ABS_POS), 6400u);       // the chip counted every step
  EXPECT_LE(chain.chip(0).axis()->true_position(), 1280);  // the rotor stayed at the stop
  EXPECT_GT(chain.chip(0).axis()->lost_steps(), 0);
}
