// ChainHost's typed API: Direction and SwitchAction in the commands, STATUS as a ChipStatus
// with named flags in positive logic, and wait_until_idle stopping at the tick BUSY rises.
#include <gtest/gtest.h>

#include "daisychain/chain.hpp"
#include "daisychain/chain_spec.hpp"
#include "daisychain/chip_status.hpp"
#include "daisychain/host.hpp"

using namespace l6470emu;

TEST(ChainHostTyped, DirectionsMoveTheWayTheyAreNamed) {
  Chain chain(2);
  ChainHost host(chain);
  host.move(0, Direction::forward, 640);
  host.move(1, Direction::reverse, 640);
  ASSERT_TRUE(host.wait_until_idle_ms(0, 1000));
  ASSERT_TRUE(host.wait_until_idle_ms(1, 1000));
  EXPECT_EQ(host.get_param(0, Reg::ABS_POS), 640u);
  EXPECT_EQ(host.get_param(1, Reg::ABS_POS), (1u << 22) - 640u);  // -640, 22-bit two's complement
  EXPECT_EQ(host.peek_status(0).direction(), Direction::forward);
  EXPECT_EQ(host.peek_status(1).direction(), Direction::reverse);
}

TEST(ChainHostTyped, PowerUpStatusReadsAsNamedFlagsAndGetStatusClearsTheLatchedOnes) {
  Chain chain(1);
  ChainHost host(chain);
  const ChipStatus s = host.status(0);
  EXPECT_EQ(s.raw(), 0x7C03);
  EXPECT_TRUE(s.hiz());
  EXPECT_FALSE(s.busy());
  EXPECT_TRUE(s.uvlo());  // active low in the register, true here
  EXPECT_FALSE(s.overcurrent());
  EXPECT_FALSE(s.stalled());
  EXPECT_EQ(s.thermal(), Thermal::normal);
  EXPECT_EQ(s.motor_status(), MotStatus::stopped);
  EXPECT_TRUE(s.any_alarm());
  EXPECT_NE(s.to_string().find("UVLO"), std::string::npos);
  EXPECT_FALSE(host.status(0).uvlo());
  EXPECT_FALSE(host.peek_status(0).any_alarm());
}

TEST(ChainHostTyped, AMoveShowsBusyAcceleratingAndAWrongCommandShowsWrongCmd) {
  Chain chain(1);
  ChainHost host(chain);
  host.status(0);
  host.run(0, Direction::forward, 0x4000);
  host.wait_ms(1);
  const ChipStatus s = host.peek_status(0);
  EXPECT_TRUE(s.busy());
  EXPECT_FALSE(s.hiz());
  EXPECT_EQ(s.motor_status(), MotStatus::acceleration);
  host.send(0, std::vector<std::uint8_t>{0xEE});  // no such opcode
  EXPECT_TRUE(host.status(0).wrong_cmd());
}

TEST(ChainHostTyped, FaultsOfEachVariantReadAsTheSameNamedFlags) {
  for (const char* spec : {"L6470", "L6480", "powerSTEP01"}) {
    SCOPED_TRACE(spec);
    Chain chain(1, *parse_chain_spec(spec).at(0));
    ChainHost host(chain);
    host.status(0);
    chain.chip(0).set_thermal(Thermal::warning);
    chain.chip(0).set_overcurrent(true);
    chain.chip(0).set_stall(Bridge::B, true);
    const ChipStatus s = host.status(0);
    EXPECT_EQ(s.thermal(), Thermal::warning);
    EXPECT_TRUE(s.overcurrent());
    EXPECT_TRUE(s.step_loss_b());
    EXPECT_FALSE(s.step_loss_a());
    EXPECT_TRUE(s.stalled());
  }
}

TEST(ChainHostTyped, WaitUntilIdleStopsAtTheTickBusyRisesWithoutAFrame) {
  Chain chain(1);
  ChainHost host(chain);
  host.move(0, Direction::forward, 3200);
  host.get_param(0, Reg::ABS_POS);
  const Tick start = chain.now();
  ASSERT_TRUE(host.wait_until_idle(0, ticks_from_ms(5000)));
  const Tick rise = chain.now();
  EXPECT_GT(rise, start);
  EXPECT_TRUE(chain.chip(0).busy_sync_pin());

  // The same commands on a second chain, one tick short of that instant: still busy.
  Chain twin(1);
  ChainHost twin_host(twin);
  twin_host.move(0, Direction::forward, 3200);
  twin_host.get_param(0, Reg::ABS_POS);
  twin.advance_to(rise - 1);
  EXPECT_FALSE(twin.chip(0).busy_sync_pin());
}

TEST(ChainHostTyped, WaitUntilIdleGivesUpAtItsTimeoutExactly) {
  Chain chain(1);
  ChainHost host(chain);
  host.run(0, Direction::reverse, 0x1000);  // runs for ever
  const Tick start = chain.now();
  EXPECT_FALSE(host.wait_until_idle_ms(0, 20));
  EXPECT_EQ(chain.now(), start + ticks_from_ms(20));
  EXPECT_TRUE(host.wait_until_idle(0, 0) == false);
  host.soft_stop(0);
  EXPECT_TRUE(host.wait_until_idle_ms(0, 1000));
}

TEST(ChainHostTyped, GoUntilTakesTheSwitchActionByName) {
  Chain chain(1);
  ChainHost host(chain);
  host.move(0, Direction::forward, 1280);
  ASSERT_TRUE(host.wait_until_idle_ms(0, 1000));
  host.go_until(0, SwitchAction::copy_to_mark, Direction::reverse, 0x4000);
  host.wait_ms(5);
  chain.chip(0).set_sw_pin(false);  // the switch closes
  ASSERT_TRUE(host.wait_until_idle_ms(0, 2000));
  EXPECT_NE(host.get_param(0, Reg::MARK), 0u);  // ABS_POS at the switch went to MARK
  EXPECT_TRUE(host.status(0).switch_event());
}
