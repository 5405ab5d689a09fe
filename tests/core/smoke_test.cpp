#include <gtest/gtest.h>

#include "support/test_support.hpp"

using namespace l6470emu;

TEST(Smoke, PowerUpStatusReads7C03ThenClears) {
  test::OneChip rig;
  EXPECT_EQ(rig.host.get_status(0), 0x7C03);
  EXPECT_EQ(rig.host.get_status(0), 0x7E03);
}
