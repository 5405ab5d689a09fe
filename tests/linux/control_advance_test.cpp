// `ctl advance` against a virtual-time board in process: the clock moves on by what it says, and
// at the end of the tick's range it refuses instead of wrapping round while reporting progress.
#include <gtest/gtest.h>

#include <string>

#include "board/board_config.hpp"
#include "core/tick.hpp"
#include "linux/device_board.hpp"
#include "linux/log.hpp"
#include "linux/serve/control.hpp"

namespace l6470emu {
namespace {

TEST(ControlAdvance, AdvanceNearTheEndOfTheClockIsRefusedAndTheClockStaysPut) {
  const ParseResult p = parse_board_config("bus=0 cs=0 chips=L6470; time=virtual", "test");
  ASSERT_TRUE(p.config);
  DiagnosticLog log("off");
  DeviceBoard board(*p.config, log);
  std::string out;
  ASSERT_EQ(run_control(board, "advance 1", out), 0) << out;
  EXPECT_EQ(out, "advanced 1 ms (4000 ticks)\n");
  ASSERT_TRUE(board.advance(kNever - 1 - 4000 - 2000));  // 2000 ticks, half a millisecond, before the end
  const Tick before = board.time().now();
  EXPECT_EQ(run_control(board, "advance 1", out), 1);
  EXPECT_EQ(out, "ctl: advance: the board's clock is at " + std::to_string(before) + " ticks and ends at " +
                     std::to_string(kNever - 1) + ": it cannot move on by 4000 ticks\n");
  EXPECT_EQ(board.time().now(), before);
  EXPECT_EQ(run_control(board, "advance 0.5", out), 0) << out;  // exactly to the end
  EXPECT_EQ(board.time().now(), kNever - 1);
}

}  // namespace
}  // namespace l6470emu
