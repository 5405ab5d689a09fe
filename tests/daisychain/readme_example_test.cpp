// The README's example, compiled and run so it cannot rot.
#include <gtest/gtest.h>

#include "daisychain/chain.hpp"
#include "daisychain/host.hpp"

using namespace l6470emu;

// BEGIN README EXAMPLE
TEST(ReadmeExample, ThreeChipsInAChainMoveIndependently) {
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
// END README EXAMPLE
