// A scripted homing session on a three-chip daisy chain: GoUntil onto a limit switch
// that the test closes when the motor physically reaches it, ReleaseSW off it, Move,
// then Run and a GoTo behind the motor (reversal mid-run). Checks positions, BUSY and
// STATUS at each step and that the other chips never notice (spec §6.3, §7).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "core/chip.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;

constexpr unsigned kDec = 2;

constexpr std::uint32_t kConfigReset = 0x2E88;
constexpr std::uint32_t kSwMode = 1u << 4;

/// The mechanics behind one chip: where the carriage physically is (in microsteps of
/// the chip's step mode) and a limit switch that is closed beyond `switch_at`.
struct Axis {
  Chain* chain = nullptr;       ///< chips are reached through Chain::chip(), which brings them up to time
  std::size_t k = 0;
  std::int64_t phys = 0;        ///< physical position, microsteps
  std::int64_t switch_at = 0;   ///< switch closed at or beyond this position
  bool switch_at_high_end = false;
  std::int32_t last_pos = 0;
  bool ever_closed = false;

  bool closed() const { return switch_at_high_end ? phys >= switch_at : phys <= switch_at; }
  /// Follows the motor's ABS_POS changes (22-bit) and drives the SW pin from the physical position.
  Chip& chip() const { return chain->chip(k); }
  void sync() {
    const std::int32_t p = chip().position();
    phys += sign_extend(static_cast<std::uint32_t>(p - last_pos), 22);
    last_pos = p;
    const bool c = closed();
    if (c != !chip().sw_pin()) {
      chip().set_sw_pin(!c);
      ever_closed = ever_closed || c;
      last_pos = chip().position();  // ACT may have reset ABS_POS: not a physical move
    }
  }
};

/// A chain of three L6470s, a host and the mechanics of each axis that moves.
struct Bench {
  Chain chain{3};
  ChainHost host{chain};
  std::deque<Axis> axes;  // stable references

  Axis& add_axis(std::size_t k, std::int64_t phys, std::int64_t switch_at, bool at_high_end) {
    Axis a;
    a.chain = &chain;
    a.k = k;
    a.phys = phys;
    a.switch_at = switch_at;
    a.switch_at_high_end = at_high_end;
    a.last_pos = a.chip().position();
    axes.push_back(a);
    return axes.back();
  }
  void sync() {
    for (auto& a : axes) a.sync();
  }
  /// Lets time pass in 16-tick chunks, keeping the switches in step with the mechanics.
  void advance(Tick ticks) {
    const Tick end = chain.now() + ticks;
    while (chain.now() < end) {
      chain.advance_to(std::min(end, chain.now() + 16));
      sync();
    }
  }
  void advance_s(double s) { advance(static_cast<Tick>(s * kTicksPerSecond)); }
  bool busy(std::size_t k) { return !chain.chip(k).busy_sync_pin(); }
  /// Advances until chip k releases BUSY; returns whether it did within `limit_s`.
  bool wait_idle(std::size_t k, double limit_s = 3.0) {
    const Tick limit = chain.now() + static_cast<Tick>(limit_s * kTicksPerSecond);
    while (busy(k)) {
      if (chain.now() >= limit) return false;
      advance(16);
    }
    return true;
  }
  std::int32_t abs_pos(std::size_t k) { return sign_extend(host.get_param(k, Reg::ABS_POS), 22); }
};

/// A chip that was never addressed: exactly as after power-up.
void expect_untouched(Bench& b, std::size_t k) {
  SCOPED_TRACE("chip " + std::to_string(k));
  Chip& c = b.chain.chip(k);
  EXPECT_EQ(c.position(), 0);
  EXPECT_TRUE(c.hiz());
  EXPECT_TRUE(c.busy_sync_pin());
  EXPECT_FALSE(c.flag_pin()) << "the power-up UVLO flag was never read away";
  EXPECT_EQ(c.status(), 0x7C03);
  EXPECT_EQ(b.host.get_param(k, Reg::STATUS), 0x7C03u);
  EXPECT_EQ(b.host.get_param(k, Reg::ABS_POS), 0u);
  EXPECT_EQ(b.host.get_param(k, Reg::MARK), 0u);
  EXPECT_EQ(b.host.get_param(k, Reg::SPEED), 0u);
  EXPECT_EQ(b.host.get_param(k, Reg::ACC), 0x08Au);
  EXPECT_EQ(b.host.get_param(k, Reg::MIN_SPEED), 0u);
  EXPECT_EQ(b.host.get_param(k, Reg::CONFIG), kConfigReset);
  EXPECT_EQ(b.host.get_param(k, Reg::STEP_MODE), 0x07u);
}

TEST(HomingScenario, MiddleChipHomesBacksOffMovesAndReversesMidRunWhileTheOthersStayPut) {
  Bench b;
  constexpr std::size_t k = 1;
  // Carriage 30000 microsteps from the machine origin; the switch closes at 10000 and below.
  Axis& axis = b.add_axis(k, 30000, 10000, /*at_high_end=*/false);

  // 0. Set-up: clear the power-up flags, profile, SW_MODE = 1 (SoftStop at the switch).
  EXPECT_EQ(b.host.get_status(k), 0x7C03);
  b.host.set_param(k, Reg::ACC, 0x100);  // 3725 step/s²
  b.host.set_param(k, Reg::DEC, 0x100);
  b.host.set_param(k, Reg::MAX_SPEED, 0x041);
  const std::uint32_t min = test::min_speed_from_steps_per_s(100);
  b.host.set_param(k, Reg::MIN_SPEED, min);
  b.host.set_param(k, Reg::CONFIG, kConfigReset | kSwMode);
  EXPECT_EQ(b.host.get_status(k), 0x7E03) << "no refused write";

  // 1. GoUntil toward the switch (reverse, ACT = 0: the switch is HOME).
  b.host.go_until(k, /*copy_to_mark=*/false, /*forward=*/false, test::spd_from_steps_per_s(400));
  b.sync();
  EXPECT_TRUE(b.busy(k));
  b.advance_s(0.2);
  EXPECT_TRUE(b.busy(k)) << "cruising, switch not reached";
  EXPECT_FALSE(axis.ever_closed);
  ASSERT_TRUE(b.wait_idle(k));
  EXPECT_TRUE(axis.ever_closed);
  EXPECT_TRUE(axis.closed()) << "SoftStop ends past the switch, on it";
  // ABS_POS was zeroed where the switch closed, then the motor decelerated from 400 to
  // 100 step/s at 3725 step/s²: 20.1 full steps = 2577 microsteps further.
  const std::int32_t after_home = b.abs_pos(k);
  EXPECT_NEAR(after_home, axis.phys - 10000, 1.0);
  EXPECT_NEAR(after_home, -2577, 2577 * 0.01);
  EXPECT_EQ(b.host.get_param(k, Reg::SPEED), 0u);
  EXPECT_EQ(b.host.get_status(k), 0x7E0E) << "enabled, SW_F, SW_EVN, reverse, stopped";

  // 2. ReleaseSW forward at MIN_SPEED until the switch opens: HOME there, HardStop.
  b.host.release_sw(k, /*copy_to_mark=*/false, /*forward=*/true);
  b.sync();
  EXPECT_TRUE(b.busy(k));
  EXPECT_EQ(b.host.get_param(k, Reg::SPEED), min << 4);
  ASSERT_TRUE(b.wait_idle(k));
  EXPECT_FALSE(axis.closed());
  EXPECT_EQ(b.abs_pos(k), 0);
  EXPECT_NEAR(static_cast<double>(axis.phys), 10001.0, 1.0);
  EXPECT_EQ(b.host.get_param(k, Reg::SPEED), 0u);
  EXPECT_EQ(b.host.get_status(k), 0x7E12) << "switch open, no new event, forward, stopped";
  const std::int64_t home_phys = axis.phys;

  // 3. Move 100 full steps forward.
  b.host.move(k, true, 12800);
  b.sync();
  EXPECT_TRUE(b.busy(k));
  ASSERT_TRUE(b.wait_idle(k));
  EXPECT_EQ(b.abs_pos(k), 12800);
  EXPECT_EQ(axis.phys, home_phys + 12800);
  EXPECT_EQ(b.host.get_status(k), 0x7E12);

  // 4. Run forward; once at speed (BUSY released) GoTo a position behind the motor.
  const std::uint32_t spd = test::spd_from_steps_per_s(600);
  b.host.run(k, true, spd);
  b.sync();
  EXPECT_TRUE(b.busy(k));
  ASSERT_TRUE(b.wait_idle(k));
  EXPECT_EQ(b.host.get_param(k, Reg::SPEED), spd);
  const std::int32_t before_goto = b.abs_pos(k);
  b.host.go_to(k, 4000);
  b.sync();
  auto s = static_cast<std::uint16_t>(b.host.get_param(k, Reg::STATUS));
  EXPECT_FALSE(s & kNotPerf) << "GoTo is accepted while the Run cruises";
  EXPECT_FALSE(s & kBusyN);
  EXPECT_TRUE(s & kDir) << "still going forward while slowing down";
  EXPECT_EQ(mot(s), kDec);
  std::int32_t furthest = before_goto;
  while (b.busy(k)) {
    b.advance(64);
    furthest = std::max(furthest, b.chain.chip(k).position());
    ASSERT_LT(b.chain.now(), Tick{20} * kTicksPerSecond);
  }
  // Slowing from 600 to 100 step/s at 3725 step/s² takes 47 full steps (6013 microsteps).
  EXPECT_NEAR(furthest - before_goto, 6013, 6013 * 0.02);
  EXPECT_EQ(b.abs_pos(k), 4000);
  EXPECT_EQ(axis.phys, home_phys + 4000);
  EXPECT_FALSE(axis.closed());
  EXPECT_EQ(b.host.get_param(k, Reg::SPEED), 0u);
  EXPECT_EQ(b.host.get_status(k), 0x7E02) << "reverse, stopped, no event, nothing refused";

  // The neighbours saw only NOPs.
  expect_untouched(b, 0);
  expect_untouched(b, 2);
}

TEST(HomingScenario, TwoChipsHomeTogetherInSharedFramesWhileTheMiddleOneStaysPut) {
  Bench b;
  // Chip 0 homes in reverse onto a switch at 2000; chip 2 homes forward onto one at 50000.
  Axis& a0 = b.add_axis(0, 15000, 2000, /*at_high_end=*/false);
  Axis& a2 = b.add_axis(2, 30000, 50000, /*at_high_end=*/true);
  const auto spd = test::spd_from_steps_per_s(500);
  const auto b2 = static_cast<std::uint8_t>(spd >> 16), b1 = static_cast<std::uint8_t>(spd >> 8),
             b0 = static_cast<std::uint8_t>(spd);
  const std::vector<std::uint8_t> nop{0x00};
  const std::vector<std::uint8_t> get_status{0xD0, 0x00, 0x00};
  b.host.send_all({get_status, nop, get_status});

  // GoUntil with SW_MODE 0 (reset): HardStop at the switch. Chip 0 copies the position
  // to MARK (ACT = 1), chip 2 makes it HOME (ACT = 0).
  b.host.send_all({{0x8A, b2, b1, b0}, nop, {0x83, b2, b1, b0}});
  b.sync();
  EXPECT_TRUE(b.busy(0));
  EXPECT_TRUE(b.busy(2));
  EXPECT_FALSE(b.busy(1));
  ASSERT_TRUE(b.wait_idle(0));
  ASSERT_TRUE(b.wait_idle(2));
  EXPECT_TRUE(a0.closed());
  EXPECT_TRUE(a2.closed());
  // HardStop: both stop where the switch closed.
  EXPECT_NEAR(static_cast<double>(a0.phys), 2000.0, 1.0);
  EXPECT_NEAR(static_cast<double>(a2.phys), 50000.0, 1.0);
  const std::int32_t p0 = b.abs_pos(0);
  EXPECT_NEAR(p0, 2000 - 15000, 1.0) << "ACT = 1 leaves ABS_POS counting";
  EXPECT_EQ(sign_extend(b.host.get_param(0, Reg::MARK), 22), p0);
  EXPECT_EQ(b.abs_pos(2), 0);

  auto frames = b.host.send_all({get_status, nop, get_status});
  EXPECT_EQ((frames[1][0] << 8) | frames[2][0], 0x7E0E) << "chip 0: SW_F, SW_EVN, reverse, stopped, enabled";
  EXPECT_EQ((frames[1][2] << 8) | frames[2][2], 0x7E1E) << "chip 2: same, forward";
  EXPECT_EQ((frames[1][1] << 8) | frames[2][1], 0x0000) << "chip 1 got NOPs: nothing to say";

  // ReleaseSW away from both switches (5 step/s with MIN_SPEED 0: 640 microsteps/s).
  b.host.send_all({{0x93}, nop, {0x92}});
  b.sync();
  ASSERT_TRUE(b.wait_idle(0, 1.0));
  ASSERT_TRUE(b.wait_idle(2, 1.0));
  EXPECT_FALSE(a0.closed());
  EXPECT_FALSE(a2.closed());
  EXPECT_EQ(b.abs_pos(0), 0);
  EXPECT_EQ(b.abs_pos(2), 0);

  // GoTo on both in the same frames.
  b.host.send_all({{0x60, 0x00, 0x0F, 0xA0}, nop, {0x60, 0x3F, 0xF0, 0x60}});  // +4000, -4000
  b.sync();
  ASSERT_TRUE(b.wait_idle(0));
  ASSERT_TRUE(b.wait_idle(2));
  EXPECT_EQ(b.abs_pos(0), 4000);
  EXPECT_EQ(b.abs_pos(2), -4000);
  EXPECT_FALSE(a0.closed());
  EXPECT_FALSE(a2.closed());

  expect_untouched(b, 1);
}

}  // namespace
}  // namespace l6470emu
