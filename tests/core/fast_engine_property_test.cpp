// The event-driven engine must agree with the tick-by-tick reference at every
// query, on random profiles and random command sequences (docs/motion-rules.md).
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "core/chip.hpp"
#include "support/engine_pair.hpp"

namespace l6470emu {
namespace {

using test::EnginePair;

/// Picks register values that cover ordinary settings and the extremes.
struct Gen {
  std::mt19937_64 rng;
  explicit Gen(std::uint64_t seed) : rng(seed) {}
  std::uint64_t below(std::uint64_t n) { return std::uniform_int_distribution<std::uint64_t>(0, n - 1)(rng); }
  bool coin() { return below(2) == 1; }
  std::uint32_t acc() {
    switch (below(7)) {
      case 0: return 1;
      case 1: return 0xFFF;
      case 2: return 0xFFE;
      case 3: return static_cast<std::uint32_t>(1 + below(0x40));
      case 4: return 1u << below(12);
      default: return static_cast<std::uint32_t>(1 + below(0xFFE));
    }
  }
  std::uint32_t max_speed() {
    switch (below(5)) {
      case 0: return 0x3FF;
      case 1: return static_cast<std::uint32_t>(1 + below(0x20));
      case 2: return 1u << below(10);  // exact divisors of a microstep: boundaries land on ticks
      default: return static_cast<std::uint32_t>(1 + below(0x3FF));
    }
  }
  std::uint32_t min_speed() {
    std::uint32_t v = below(3) == 0 ? 0 : static_cast<std::uint32_t>(below(0x1000));
    if (below(4) == 0) v |= 0x1000;  // LSPD_OPT
    return v;
  }
  std::uint32_t speed() { return below(5) == 0 ? static_cast<std::uint32_t>(below(0x100000)) : static_cast<std::uint32_t>(below(0x30000)); }
  std::uint32_t steps() {
    switch (below(6)) {
      case 0: return static_cast<std::uint32_t>(below(4));
      case 1: return 0x3FFFFF;
      default: return static_cast<std::uint32_t>(below(20000));
    }
  }
  Tick gap() {
    switch (below(5)) {
      case 0: return below(4);
      case 1: return below(400);
      case 2: return below(40'000);
      default: return below(200'000);
    }
  }
};

void configure(EnginePair& p, Gen& g) {
  p.bytes({0xA8});  // HardHiZ so every register is writable
  p.set2(0x05, g.acc());
  p.set2(0x06, g.acc());
  p.set2(0x07, g.max_speed());
  p.set2(0x08, g.min_speed());
  p.set1(0x16, static_cast<std::uint32_t>(g.below(8)));                     // STEP_SEL 0..7
  p.set2(0x18, 0x2E88 | (g.coin() ? 0x10u : 0u));                           // SW_MODE either way
  if (g.below(3) == 0) p.cmd3(0x01 /*ABS_POS*/, static_cast<std::uint32_t>(0x1FFF00 + g.below(0x200)));  // near +2^21
}

void random_command(EnginePair& p, Gen& g) {
  const bool dir = g.coin();
  switch (g.below(14)) {
    case 0: case 1: p.cmd3(static_cast<std::uint8_t>(0x50 | dir), g.speed()); break;      // Run
    case 2: case 3: p.cmd3(static_cast<std::uint8_t>(0x40 | dir), g.steps()); break;      // Move
    case 4: p.cmd3(0x60, static_cast<std::uint32_t>(g.below(0x400000))); break;           // GoTo
    case 5: p.cmd3(static_cast<std::uint8_t>(0x68 | dir), static_cast<std::uint32_t>(g.below(0x400000))); break;
    case 6: p.cmd3(static_cast<std::uint8_t>(0x82 | (g.coin() ? 8 : 0) | dir), g.speed()); break;  // GoUntil
    case 7: p.bytes({static_cast<std::uint8_t>(0x92 | (g.coin() ? 8 : 0) | dir)}); break;          // ReleaseSW
    case 8: p.bytes({g.coin() ? std::uint8_t{0xB0} : std::uint8_t{0xA0}}); break;                  // SoftStop/SoftHiZ
    case 9: p.bytes({g.coin() ? std::uint8_t{0xB8} : std::uint8_t{0xA8}}); break;                  // HardStop/HardHiZ
    case 10: p.set2(0x07, g.max_speed()); break;                                                    // MAX_SPEED (WR)
    case 11: p.sw(!g.coin()); break;                                                                // switch edge
    case 12: p.bytes({static_cast<std::uint8_t>(0x58 | dir)}); p.stck(true); p.stck(false); break;  // StepClock
    case 13: p.bytes({0x70}); break;                                                                // GoHome
  }
}

TEST(FastEngine, AgreesWithTheReferenceOnRandomProfilesAndCommandSequences) {
  for (std::uint64_t seed = 1; seed <= 2000; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    Gen g(seed);
    EnginePair p;
    configure(p, g);
    Tick t = 0;
    const int commands = 1 + static_cast<int>(g.below(8));
    for (int c = 0; c < commands; ++c) {
      random_command(p, g);
      for (int q = static_cast<int>(g.below(4)); q >= 0; --q) {
        t += g.gap();
        p.advance_to(t);
        if (g.coin()) {
          // Poll as a host does: GetStatus over SPI, answered from the flags without
          // working the motion out when the fast engine knows they cannot have changed.
          const std::uint8_t fast_cmd = p.fast.on_byte(0xD0), ref_cmd = p.ref.on_byte(0xD0);
          ASSERT_EQ(fast_cmd, ref_cmd);
          ASSERT_EQ(p.fast.on_byte(0x00), p.ref.on_byte(0x00));
          ASSERT_EQ(p.fast.on_byte(0x00), p.ref.on_byte(0x00));
          continue;
        }
        ASSERT_TRUE(test::same_motion(p.fast, p.ref));
      }
    }
  }
}

TEST(FastEngine, AgreesOnAFullLengthMoveOf2To22Minus1MicrostepsWithWrap) {
  EnginePair p;
  p.bytes({0xA8});
  p.set2(0x05, 0xFFF);  // infinite acceleration
  p.set2(0x07, 0x3FF);
  p.cmd3(0x41, 0x3FFFFF);
  for (Tick t = 1'000'003; t < 12'000'000; t += 1'000'003) {
    p.advance_to(t);
    ASSERT_TRUE(test::same_motion(p.fast, p.ref));
  }
  p.advance_to(12'000'000);
  EXPECT_TRUE(test::same_motion(p.fast, p.ref));
  EXPECT_EQ(p.fast.position(), -1);  // 2^22 - 1 steps forward from 0 wraps to -1
}

TEST(FastEngine, AgreesWithAcc1AndDec1OverALongRamp) {
  EnginePair p;
  p.bytes({0xA8});
  p.set2(0x05, 1);
  p.set2(0x06, 1);
  p.set2(0x07, 0x3FF);
  p.cmd3(0x51, 0xFFFFF);
  for (Tick t = 777'777; t < 8'000'000; t += 777'777) {
    p.advance_to(t);
    ASSERT_TRUE(test::same_motion(p.fast, p.ref));
  }
  p.bytes({0xB0});  // SoftStop at DEC = 1
  for (Tick t = 8'000'000; t < 16'000'000; t += 999'999) {
    p.advance_to(t);
    ASSERT_TRUE(test::same_motion(p.fast, p.ref));
  }
}

}  // namespace
}  // namespace l6470emu

namespace l6470emu {
namespace {

TEST(FastEngine, StopsExactlyWhenTheLastMicrostepEndsOnATickBoundary) {
  EnginePair p;
  p.bytes({0xA8});
  p.set2(0x05, 0xFFF);  // infinite acceleration: constant 2^31 per tick
  p.set2(0x07, 0x200);
  p.set1(0x16, 0x00);   // full steps: one step is 2^40, i.e. exactly 512 ticks
  p.cmd3(0x41, 3);
  for (Tick t : {511u, 512u, 1535u, 1536u, 1537u, 5000u}) {
    p.advance_to(t);
    ASSERT_TRUE(test::same_motion(p.fast, p.ref)) << "tick " << t;
  }
  EXPECT_EQ(p.fast.position(), 3);
  EXPECT_EQ(p.fast.motion().activity, Activity::idle);
}

}  // namespace
}  // namespace l6470emu
