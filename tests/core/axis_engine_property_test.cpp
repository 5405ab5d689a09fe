// With axes attached the event-driven engine must still agree with the tick-by-tick one: same
// registers, STATUS and pins, and the same mechanical state (true position, synchronism,
// switch contacts, stall and overcurrent conditions) at every query, on random profiles, loads,
// switches, hard stops and command sequences. The tick of a switch edge shows in MARK (GoUntil
// with ACT = 1 copies ABS_POS there) and in where a HardStop at the switch leaves the motor.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>

#include "core/chip.hpp"
#include "support/engine_pair.hpp"

namespace l6470emu {
namespace {

using test::EnginePair;

::testing::AssertionResult same(const Chip& f, const Chip& r) {
  if (auto motion = test::same_motion(f, r); !motion) return motion;
  if (f.sw_pin() != r.sw_pin()) return ::testing::AssertionFailure() << "SW pin differs at tick " << r.now();
  const Axis& a = *f.axis();
  const Axis& b = *r.axis();
  if (a.true_position() != b.true_position() || a.synchronised() != b.synchronised() ||
      a.stall_condition() != b.stall_condition() || a.overcurrent_condition() != b.overcurrent_condition() ||
      a.lost_steps() != b.lost_steps())
    return ::testing::AssertionFailure() << "axis differs at tick " << r.now() << ": true " << a.true_position() << " vs "
                                         << b.true_position() << ", synced " << a.synchronised() << " vs "
                                         << b.synchronised() << ", stall " << a.stall_condition() << " vs "
                                         << b.stall_condition() << ", ocd " << a.overcurrent_condition() << " vs "
                                         << b.overcurrent_condition();
  for (std::size_t i = 0; i < a.spec().switches.size(); ++i)
    if (a.switch_actuated(i) != b.switch_actuated(i) || a.switch_closed(i) != b.switch_closed(i))
      return ::testing::AssertionFailure() << "switch " << i << " differs at tick " << r.now();
  return ::testing::AssertionSuccess();
}

struct Gen {
  std::mt19937_64 rng;
  explicit Gen(std::uint64_t seed) : rng(seed) {}
  std::uint64_t below(std::uint64_t n) { return std::uniform_int_distribution<std::uint64_t>(0, n - 1)(rng); }
  std::int64_t between(std::int64_t lo, std::int64_t hi) { return std::uniform_int_distribution<std::int64_t>(lo, hi)(rng); }
  bool coin() { return below(2) == 1; }
};

AxisSpec random_axis(Gen& g) {
  AxisSpec s;
  s.start_position = g.between(-20'000, 20'000);
  if (g.coin()) {
    s.has_lower_stop = true;
    s.lower_stop = s.start_position - g.between(0, 25'000);
  }
  if (g.coin()) {
    s.has_upper_stop = true;
    s.upper_stop = s.start_position + g.between(0, 25'000);
  }
  s.load.friction_uNm = static_cast<std::uint32_t>(g.below(4) == 0 ? 0 : g.below(150'000));
  s.load.inertia_g_mm2 = static_cast<std::uint32_t>(g.below(50'000));
  s.load.force_uNm = static_cast<std::int32_t>(g.below(3) == 0 ? g.between(-200'000, 200'000) : 0);
  s.pull_in_speed_steps_per_s = static_cast<std::uint32_t>(g.below(3) == 0 ? g.below(400) : 0);
  s.supply.supply_mV = static_cast<std::uint32_t>(g.between(8'000, 48'000));
  const int switches = static_cast<int>(g.below(4));
  for (int i = 0; i < switches; ++i) {
    SwitchSpec w;
    w.position = s.start_position + g.between(-30'000, 30'000);
    w.above = g.coin();
    w.normally_closed = g.below(4) == 0;
    w.hysteresis = g.below(3) == 0 ? 0 : g.between(0, 300);
    if (g.below(3) == 0) {
      w.bounce_count = static_cast<std::uint32_t>(1 + g.below(3));
      w.bounce_ticks = 1 + g.below(2000);
    }
    s.switches.push_back(w);
  }
  return s;
}

void configure(EnginePair& p, Gen& g) {
  p.bytes({0xA8});  // HardHiZ: every register writable
  auto acc = [&] { return static_cast<std::uint32_t>(g.below(5) == 0 ? 0xFFF : 1 + g.below(0x400)); };
  p.set2(0x05, acc());
  p.set2(0x06, acc());
  p.set2(0x07, static_cast<std::uint32_t>(1 + g.below(0x100)));  // MAX_SPEED up to ~3900 step/s
  p.set2(0x08, static_cast<std::uint32_t>(g.below(3) == 0 ? 0 : g.below(0x400)) | (g.below(4) == 0 ? 0x1000u : 0u));
  for (std::uint8_t kval = 0x09; kval <= 0x0C; ++kval) p.set1(kval, static_cast<std::uint32_t>(g.below(0x60)));
  p.set2(0x0D, static_cast<std::uint32_t>(g.below(0x3FFF)));  // INT_SPEED
  for (std::uint8_t slp = 0x0E; slp <= 0x10; ++slp) p.set1(slp, static_cast<std::uint32_t>(g.below(0x60)));
  p.set1(0x13, static_cast<std::uint32_t>(g.below(16)));   // OCD_TH
  p.set1(0x14, static_cast<std::uint32_t>(g.below(128)));  // STALL_TH
  p.set1(0x16, static_cast<std::uint32_t>(g.below(8)));    // STEP_SEL
  p.set2(0x18, (g.coin() ? 0x2E88u : 0x2E08u) | (g.coin() ? 0x10u : 0u));  // OC_SD and SW_MODE either way
}

void random_command(EnginePair& p, Gen& g) {
  const bool dir = g.coin();
  const auto spd = [&] { return static_cast<std::uint32_t>(g.below(0x10000)); };
  switch (g.below(12)) {
    case 0: case 1: p.cmd3(static_cast<std::uint8_t>(0x50 | dir), spd()); break;                      // Run
    case 2: case 3: p.cmd3(static_cast<std::uint8_t>(0x40 | dir), static_cast<std::uint32_t>(g.below(60'000))); break;
    case 4: p.cmd3(0x60, static_cast<std::uint32_t>(g.below(0x400000))); break;                        // GoTo
    case 5: p.cmd3(static_cast<std::uint8_t>(0x82 | (g.coin() ? 8 : 0) | dir), spd()); break;          // GoUntil
    case 6: p.bytes({static_cast<std::uint8_t>(0x92 | (g.coin() ? 8 : 0) | dir)}); break;             // ReleaseSW
    case 7: p.bytes({g.coin() ? std::uint8_t{0xB0} : std::uint8_t{0xA0}}); break;                      // SoftStop/SoftHiZ
    case 8: p.bytes({g.coin() ? std::uint8_t{0xB8} : std::uint8_t{0xA8}}); break;                      // HardStop/HardHiZ
    case 9: p.bytes({0xD0, 0x00, 0x00}); break;                                                         // GetStatus
    case 10: p.set1(0x0A, static_cast<std::uint32_t>(g.below(0x60))); break;                           // KVAL_RUN (WR)
    case 11: p.bytes({0x70}); break;                                                                     // GoHome
  }
}

TEST(AxisEngines, AgreeOnRandomAxesProfilesAndCommandSequences) {
  // How often the sessions meet each mechanical event, so the agreement means something.
  int lost = 0, at_stop = 0, switch_on = 0, stall = 0, ocd = 0;
  for (std::uint64_t seed = 1; seed <= 250; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    Gen g(seed);
    EnginePair p;
    configure(p, g);
    p.attach(random_axis(g));
    ASSERT_TRUE(same(p.fast, p.ref));
    Tick t = 0;
    const int commands = 1 + static_cast<int>(g.below(8));
    for (int c = 0; c < commands; ++c) {
      random_command(p, g);
      for (int q = static_cast<int>(g.below(4)); q >= 0; --q) {
        t += g.below(3) == 0 ? g.below(500) : g.below(150'000);
        p.advance_to(t);
        ASSERT_TRUE(same(p.fast, p.ref));
        const Axis& a = *p.fast.axis();
        lost += a.lost_steps() != 0;
        at_stop += a.at_stop();
        switch_on += !p.fast.sw_pin();
        stall += a.stall_condition();
        ocd += (p.fast.status() & (1u << 12)) == 0;
      }
    }
  }
  EXPECT_GT(lost, 50);
  EXPECT_GT(at_stop, 20);  // stops within 25000 units of the start
  EXPECT_GT(switch_on, 50);
  EXPECT_GT(stall, 10);
  EXPECT_GT(ocd, 10);
  std::printf("queries with lost steps %d, at a stop %d, SW low %d, stalling %d, OCD shown %d\n", lost, at_stop,
              switch_on, stall, ocd);
}

TEST(AxisEngines, AgreeWhenSampledEvery997TicksOverWholeSessions) {
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    Gen g(seed * 7919);
    EnginePair p;
    configure(p, g);
    p.attach(random_axis(g));
    Tick t = 0;
    for (int c = 0; c < 3; ++c) {
      random_command(p, g);
      const Tick end = t + g.below(40'000);
      // Both chips are only looked at every 997 ticks: the fast one jumps in between.
      for (; t < end; t += 997) {
        p.advance_to(t);
        ASSERT_TRUE(same(p.fast, p.ref));
      }
    }
  }
}

}  // namespace
}  // namespace l6470emu
