// Host sessions against axes with physics, through SPI bytes on a three-chip chain: homing
// on a switch that closes by itself when the carriage gets there, sensorless homing into a
// hard stop, and an overloaded fast move whose lost steps the host finds with the switch.
#include <gtest/gtest.h>

#include <cstdint>

#include "core/chip.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;

constexpr std::int64_t kStep = kAxisUnitsPerStep;
constexpr std::size_t kMiddle = 1;

/// Three L6470s; chip 1 has the axis, the others none.
struct Machine {
  Chain chain{3};
  ChainHost host{chain};
  explicit Machine(const AxisSpec& spec) {
    chain.chip(kMiddle).attach_axis(spec);
    for (std::size_t k = 0; k < 3; ++k) host.get_status(k);
  }
  const Axis& axis() { return *chain.chip(kMiddle).axis(); }
  bool flag() { return chain.chip(kMiddle).flag_pin(); }
  bool busy() { return !chain.chip(kMiddle).busy_sync_pin(); }
  std::int32_t abs_pos() { return sign_extend(host.get_param(kMiddle, Reg::ABS_POS), 22); }
  /// Polls GetStatus every millisecond until BUSY is released; returns the last STATUS.
  std::uint16_t wait_idle(std::uint64_t limit_ms = 30'000) {
    std::uint16_t st = 0;
    for (std::uint64_t i = 0; i < limit_ms; ++i) {
      st = static_cast<std::uint16_t>(host.get_param(kMiddle, Reg::STATUS));
      if (st & kBusyN) return st;
      host.wait_ms(1);
    }
    ADD_FAILURE() << "still busy";
    return st;
  }
};

AxisSpec home_switch_axis() {
  AxisSpec spec;
  spec.has_lower_stop = true;
  spec.lower_stop = -20 * kStep;
  spec.has_upper_stop = true;
  spec.upper_stop = 2000 * kStep;
  spec.start_position = 900 * kStep;  // the carriage starts somewhere along the travel
  SwitchSpec home;
  home.position = 100;  // just below 1 full step
  home.hysteresis = 8;
  spec.switches.push_back(home);
  return spec;
}

TEST(AxisScenario, HomingWithGoUntilAndReleaseSwStopsWhereTheSwitchReallyIs) {
  Machine m(home_switch_axis());
  EXPECT_TRUE(m.chain.chip(kMiddle).sw_pin()) << "switch open far from home";
  // GoUntil reverse at 400 step/s, ACT = 0; SW_MODE = 0: HardStop at the switch.
  m.host.go_until(kMiddle, false, false, test::spd_from_steps_per_s(400));
  m.host.wait_ms(100);
  EXPECT_TRUE(m.busy());
  std::uint16_t st = m.wait_idle();
  EXPECT_TRUE(st & kSwF) << "stopped on the closed switch";
  EXPECT_TRUE(st & kSwEvn);
  EXPECT_EQ(m.abs_pos(), 0) << "HOME where the switch closed";
  EXPECT_EQ(m.axis().true_position(), 100) << "the switch closes at its position";
  EXPECT_EQ(m.axis().lost_steps(), 0);
  // ReleaseSW forward: off the switch at MIN_SPEED (5 step/s floor), HOME where it opens.
  m.host.get_status(kMiddle);
  m.host.release_sw(kMiddle, false, true);
  st = m.wait_idle();
  EXPECT_FALSE(st & kSwF);
  EXPECT_EQ(m.abs_pos(), 0);
  EXPECT_EQ(m.axis().true_position(), 100 + 8 + 1) << "released past the hysteresis";
  // Now a GoTo lands where the machine says it is.
  m.host.go_to(kMiddle, 12'800);
  m.wait_idle();
  EXPECT_EQ(m.axis().true_position(), 109 + 12'800);
  EXPECT_TRUE(m.flag());
}

TEST(AxisScenario, SensorlessHomingRunsIntoTheHardStopAndTheHostSeesFlagFall) {
  AxisSpec spec;
  spec.has_lower_stop = true;
  spec.lower_stop = 0;
  spec.start_position = 300 * kStep;
  Machine m(spec);
  // Low KVAL, and STALL_TH between the following rotor's current and the blocked one's.
  m.host.set_param(kMiddle, Reg::KVAL_RUN, 0x10);
  m.host.set_param(kMiddle, Reg::KVAL_ACC, 0x10);
  m.host.set_param(kMiddle, Reg::KVAL_DEC, 0x10);
  m.host.set_param(kMiddle, Reg::STALL_TH, 18);  // 0.59 A
  m.host.get_status(kMiddle);
  m.host.run(kMiddle, false, test::spd_from_steps_per_s(100));
  // The host waits for FLAG, as a real one would on an interrupt line.
  std::uint64_t ms = 0;
  while (m.flag() && ms < 10'000) {
    m.host.wait_ms(1);
    ++ms;
  }
  ASSERT_FALSE(m.flag()) << "no stall detected";
  EXPECT_NEAR(static_cast<double>(ms), 3000.0, 60.0) << "300 full steps at 100 step/s";
  const std::uint16_t st = m.host.get_status(kMiddle);
  EXPECT_EQ(st & (kStepLossAN | kStepLossBN), 0) << "STEP_LOSS_A and STEP_LOSS_B";
  m.host.hard_stop(kMiddle);
  m.host.reset_pos(kMiddle);
  EXPECT_EQ(m.abs_pos(), 0);
  EXPECT_TRUE(m.axis().at_stop() || m.axis().true_position() <= 2 * kStep)
      << "at the stop, or pulled to the nearest full-step equilibrium within two full steps";
  EXPECT_GE(m.axis().true_position(), 0);
  m.host.get_status(kMiddle);
  EXPECT_TRUE(m.flag()) << "nothing left once stopped and read";
  // From there the axis is homed: back to the running KVAL, GoTo 100 full steps lands 100
  // full steps from the stop.
  m.host.set_param(kMiddle, Reg::KVAL_RUN, 0x29);
  m.host.set_param(kMiddle, Reg::KVAL_ACC, 0x29);
  m.host.set_param(kMiddle, Reg::KVAL_DEC, 0x29);
  const std::int64_t zero = m.axis().true_position();
  m.host.go_to(kMiddle, 100 * 128);
  m.wait_idle();
  EXPECT_NEAR(static_cast<double>(m.axis().true_position()), static_cast<double>(zero + 100 * 128), 2.0 * kStep)
      << "less the part of a step the rotor was pressed into the stop";
  EXPECT_TRUE(m.axis().synchronised());
}

TEST(AxisScenario, AnOverloadedFastMoveLosesStepsAndTheHostFindsThemWithTheSwitch) {
  AxisSpec spec = home_switch_axis();
  spec.start_position = 50 * kStep;
  Machine m(spec);
  // Home first (HardStop at the switch, HOME there).
  m.host.go_until(kMiddle, false, false, test::spd_from_steps_per_s(200));
  m.wait_idle();
  m.host.release_sw(kMiddle, false, true);
  m.wait_idle();
  ASSERT_EQ(m.abs_pos(), 0);
  m.host.get_status(kMiddle);
  // A heavy, sticky load appears; the host asks for a fast long move anyway.
  LoadSpec load;
  load.inertia_g_mm2 = 20'000;
  load.friction_uNm = 60'000;
  m.chain.chip(kMiddle).set_axis_load(load);
  m.host.set_param(kMiddle, Reg::MAX_SPEED, test::max_speed_from_steps_per_s(1500));
  m.host.move(kMiddle, true, 1000 * 128);
  m.wait_idle();
  EXPECT_EQ(m.abs_pos(), 1000 * 128) << "the chip counted every step";
  const std::int64_t lost = m.axis().lost_steps();
  EXPECT_GT(lost, 0);
  // Slowly back home. SW_MODE = 0: the switch stops the motor where it really closes.
  m.host.set_param(kMiddle, Reg::MAX_SPEED, test::max_speed_from_steps_per_s(150));
  m.host.go_home(kMiddle);
  const std::uint16_t st = m.wait_idle();
  EXPECT_TRUE(st & kSwEvn) << "the switch closed before ABS_POS reached 0";
  const std::int32_t seen = m.abs_pos();
  EXPECT_GT(seen, 0);
  // The host's estimate of the loss: where the switch closed versus where it should (-9: the
  // switch closes 9 units below the released point that became HOME).
  EXPECT_EQ(seen + 9, lost);
  EXPECT_EQ(lost % (4 * kStep), 0);
}

}  // namespace
}  // namespace l6470emu
