// Chip::output_levels(): the BUSY, FLAG and SW levels a recording watches, and the tick through
// which it may trust them without looking again (steady_through). The promise is checked
// against the chip itself, moved on by copies, over random moves, runs, stops and polls.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>

#include "core/chip.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

struct Levels {
  bool busy, flag, sw;
  friend bool operator==(const Levels&, const Levels&) = default;
};

Levels pins_of(const Chip& chip) { return {chip.busy_sync_pin(), chip.flag_pin(), chip.sw_pin()}; }

/// Chip `chip` moved on to `t` (a copy: the original is not touched).
Levels levels_at(const Chip& chip, Tick t) {
  Chip probe = chip;
  probe.advance_to(t);
  return pins_of(probe);
}

TEST(OutputLevels, AreThePinsAndStayAsTheyAreThroughTheTickTheyPromise) {
  std::mt19937 random(0x6470);
  int promises_beyond_now = 0, samples = 0;
  for (int round = 0; round < 40; ++round) {
    test::OneChip r;
    r.host.set_param(0, Reg::ACC, 0x20 + random() % 0x400);
    r.host.set_param(0, Reg::DEC, 0x20 + random() % 0x400);
    r.host.set_param(0, Reg::MAX_SPEED, 0x10 + random() % 0x60);
    for (int step = 0; step < 12; ++step) {
      switch (random() % 6) {
        case 0: r.host.move(0, random() % 2 == 0, 1 + random() % 40000); break;
        case 1: r.host.run(0, random() % 2 == 0, random() % 0x8000); break;
        case 2: r.host.soft_stop(0); break;
        case 3: r.host.get_status(0); break;  // a poll: the cached STATUS (the fast look)
        case 4: r.host.go_to(0, static_cast<std::int32_t>(random() % 100000) - 50000); break;
        default: break;
      }
      for (int look = 0; look < 8; ++look) {
        r.host.wait(1 + random() % ticks_from_ms(40));
        if (random() % 2 == 0) r.host.get_status(0);
        const Chip& chip = r.chip();
        const Chip::OutputLevels o = chip.output_levels();
        const Levels now{o.busy, o.flag, o.sw};
        ASSERT_EQ(now, pins_of(chip)) << "round " << round << ", step " << step;
        ASSERT_GE(o.steady_through, chip.now());
        ++samples;
        if (o.steady_through == chip.now()) continue;
        ++promises_beyond_now;
        const Tick last = o.steady_through == kNever ? chip.now() + ticks_from_ms(2000) : o.steady_through;
        ASSERT_EQ(levels_at(chip, last), now) << "round " << round << ", step " << step << ": the levels changed by "
                                              << last << ", promised steady through " << o.steady_through;
        const Tick between = chip.now() + static_cast<Tick>(random() % (last - chip.now() + 1));
        ASSERT_EQ(levels_at(chip, between), now) << "round " << round << ", step " << step << " at " << between;
      }
    }
  }
  // Not a vacuous promise: most looks are inside a run of uniform ticks or idle.
  EXPECT_GT(promises_beyond_now, samples / 2) << promises_beyond_now << " of " << samples;
}

TEST(OutputLevels, PromiseNothingBeyondNowWhereBusyIsTheSyncClock) {
  test::OneChip r;
  r.host.set_param(0, Reg::STEP_MODE, 0x80 | 0x07);  // SYNC_EN: BUSY\SYNC is a step clock
  r.host.run(0, true, 0x4000);
  r.host.wait(ticks_from_ms(200));
  const Chip& chip = r.chip();
  EXPECT_EQ(chip.output_levels().steady_through, chip.now());
}

TEST(OutputLevels, PromiseForeverForAnIdleChipWithoutAnAxis) {
  test::OneChip r;
  r.host.get_status(0);
  EXPECT_EQ(r.chip().output_levels().steady_through, kNever);
}

}  // namespace
}  // namespace l6470emu
