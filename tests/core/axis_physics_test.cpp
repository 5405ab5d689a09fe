// One test per rule of the mechanical axis (docs/chip-model.md, "The mechanical world"):
// torque from KVAL, supply and back-EMF, loss of synchronism in whole electrical cycles, hard
// stops, the stall and overcurrent comparators of each family, switches, and no axis at all.
#include <gtest/gtest.h>

#include <cstdint>

#include "core/axis.hpp"
#include "core/chip.hpp"
#include "core/drive_model.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;

/// One chip of `variant` with an axis behind it and a host talking SPI to it.
struct Rig {
  Chain chain;
  ChainHost host{chain};
  explicit Rig(const AxisSpec& spec, const Variant& variant = l6470()) : chain(1, variant) {
    chain.chip(0).attach_axis(spec);
    host.get_status(0);  // read away the power-up UVLO flag
  }
  Chip& chip() { return chain.chip(0); }
  const Axis& axis() { return *chain.chip(0).axis(); }
  void wait_ms(std::uint64_t ms) { host.wait_ms(ms); }
  /// Waits until BUSY is released (at most `limit_ms`).
  bool wait_idle(std::uint64_t limit_ms = 20'000) {
    for (std::uint64_t i = 0; i < limit_ms; ++i) {
      if (chip().busy_sync_pin()) return true;
      wait_ms(1);
    }
    return chip().busy_sync_pin();
  }
};

constexpr std::int64_t kStep = kAxisUnitsPerStep;  // one full step in axis units

TEST(AxisPhysics, WithoutAnAxisTheChipHasNone) {
  Chip chip;
  EXPECT_EQ(chip.axis(), nullptr);
  chip.set_axis_load({});  // harmless
  EXPECT_EQ(chip.axis(), nullptr);
}

TEST(AxisPhysics, AnAxisThatKeepsUpChangesNothingTheHostSees) {
  // Same commands to a chip with a default (unloaded NEMA-17) axis and to one without.
  Chain plain(1), with_axis(1);
  with_axis.chip(0).attach_axis(AxisSpec{});
  ChainHost a(plain), b(with_axis);
  std::vector<std::uint32_t> answers_a, answers_b;
  auto both = [&](auto&& f) {
    f(a);
    f(b);
  };
  both([](ChainHost& h) { h.get_status(0); });
  both([](ChainHost& h) { h.move(0, true, 50'000); });
  for (int i = 0; i < 40; ++i) {
    both([](ChainHost& h) { h.wait_ms(50); });
    answers_a.push_back(a.get_status(0));
    answers_b.push_back(b.get_status(0));
    answers_a.push_back(a.get_param(0, Reg::ABS_POS));
    answers_b.push_back(b.get_param(0, Reg::ABS_POS));
  }
  both([](ChainHost& h) { h.run(0, false, test::spd_from_steps_per_s(300)); });
  both([](ChainHost& h) { h.wait_ms(700); });
  both([](ChainHost& h) { h.soft_stop(0); });
  both([](ChainHost& h) { h.wait_ms(700); });
  answers_a.push_back(a.get_status(0));
  answers_b.push_back(b.get_status(0));
  answers_a.push_back(a.get_param(0, Reg::ABS_POS));
  answers_b.push_back(b.get_param(0, Reg::ABS_POS));
  EXPECT_EQ(answers_a, answers_b);
  EXPECT_EQ(with_axis.chip(0).axis()->lost_steps(), 0);
  EXPECT_TRUE(plain.chip(0).flag_pin());
  EXPECT_TRUE(with_axis.chip(0).flag_pin());
}

TEST(AxisPhysics, TheRotorFollowsTheCommandedPositionWhileSynchronised) {
  AxisSpec spec;
  spec.start_position = 1000;
  Rig r(spec);
  r.host.move(0, true, 25'600);  // 200 full steps
  ASSERT_TRUE(r.wait_idle());
  EXPECT_EQ(r.axis().true_position(), 1000 + 25'600);
  EXPECT_TRUE(r.axis().synchronised());
  r.host.hard_hiz(0);
  r.host.set_param(0, Reg::STEP_MODE, 0x03);  // 1/8 step: a microstep is 16 axis units
  r.host.move(0, false, 80);
  ASSERT_TRUE(r.wait_idle());
  EXPECT_EQ(r.axis().true_position(), 1000 + 25'600 - 80 * 16);
}

TEST(AxisPhysics, DriveCurrentFallsWithBackEmfAndRisesWhenTheRotorIsBlocked) {
  AxisSpec spec;
  DriveInputs in;
  in.level = {0x29, 0x29, 0x29, 0x29};
  in.st_slp = 0x19;
  in.fn_slp_acc = in.fn_slp_dec = 0x29;
  in.int_speed = 0x408;
  const DrivePoint still = drive_point(spec, in, DrivePhase::hold, 0);
  // 12 V · 41/256 = 1.92 V over 1.5 Ω
  EXPECT_EQ(still.voltage_mV, 1921u);
  EXPECT_EQ(still.sync_mA, 1280u);
  const std::uint32_t band400 = speed_band(std::uint64_t{test::max_speed_from_steps_per_s(400)} << 22);
  const DrivePoint fast = drive_point(spec, in, DrivePhase::run, band400);
  EXPECT_GT(fast.voltage_mV, still.voltage_mV) << "BEMF compensation raises the voltage with speed";
  EXPECT_NEAR(fast.emf_mV, 3250, 60) << "k_e = 0.259 V·s/rad at 400 step/s";
  EXPECT_LT(fast.sync_mA, still.sync_mA);
  EXPECT_GT(fast.blocked_mA, fast.sync_mA) << "no back-EMF when the rotor stands";
  EXPECT_LT(fast.torque_uNm, still.torque_uNm);
}

TEST(AxisPhysics, WithBemfCompensationMatchedToTheMotorAFastRunKeepsSynchronism) {
  AxisSpec spec;
  Rig r(spec);
  r.host.hard_hiz(0);
  // k_e = 8.13 mV per step/s on a 12 V supply: 44 · 2^-16 VS per step/s.
  r.host.set_param(0, Reg::ST_SLP, 44);
  r.host.set_param(0, Reg::FN_SLP_ACC, 44);
  r.host.set_param(0, Reg::FN_SLP_DEC, 44);
  r.host.set_param(0, Reg::MAX_SPEED, test::max_speed_from_steps_per_s(1200));
  r.host.run(0, true, test::spd_from_steps_per_s(1200));
  r.wait_ms(1500);
  EXPECT_TRUE(r.axis().synchronised());
  EXPECT_EQ(r.axis().lost_steps(), 0);
  EXPECT_EQ(r.axis().true_position() - spec.start_position, r.chip().position());
}

TEST(AxisPhysics, WithoutBemfCompensationAFastRunLosesSteps) {
  AxisSpec spec;
  Rig r(spec);
  r.host.hard_hiz(0);
  r.host.set_param(0, Reg::ST_SLP, 0);
  r.host.set_param(0, Reg::FN_SLP_ACC, 0);
  r.host.set_param(0, Reg::FN_SLP_DEC, 0);
  r.host.set_param(0, Reg::MAX_SPEED, test::max_speed_from_steps_per_s(1200));
  r.host.run(0, true, test::spd_from_steps_per_s(1200));
  r.wait_ms(1500);
  EXPECT_FALSE(r.axis().synchronised()) << "back-EMF above 1.9 V from ~240 step/s leaves no current";
  EXPECT_GT(r.axis().lost_steps(), 100 * kStep);
  EXPECT_GT(r.chip().position(), 1500 * 100) << "ABS_POS keeps counting";
}

TEST(AxisPhysics, LostStepsAreMultiplesOfFourFullSteps) {
  AxisSpec spec;
  spec.start_position = 1000;  // not on a full step: the electrical phase is kept all the same
  spec.load.friction_uNm = 60'000;  // 0.06 N·m
  Rig r(spec);
  r.host.set_param(0, Reg::MAX_SPEED, test::max_speed_from_steps_per_s(1500));
  r.host.move(0, true, 200 * 128 * 10);
  ASSERT_TRUE(r.wait_idle());
  const std::int64_t lost = r.axis().lost_steps();
  EXPECT_GT(lost, 0);
  EXPECT_EQ(lost % (4 * kStep), 0) << lost;
  EXPECT_TRUE(r.axis().synchronised()) << "pulled back in once stopped";
}

TEST(AxisPhysics, AConstantForceWithFrictionLosesStepsAgainstItButNotWithIt) {
  AxisSpec spec;
  spec.load.force_uNm = 100'000;    // pushes toward negative positions
  spec.load.friction_uNm = 40'000;  // against: 0.14 N·m needed; with it: 0.06 N·m
  Rig r(spec);
  r.host.set_param(0, Reg::KVAL_ACC, 0x10);  // 0.13 N·m at standstill, 0.08 N·m at 80 step/s
  r.host.set_param(0, Reg::KVAL_RUN, 0x10);
  r.host.set_param(0, Reg::KVAL_DEC, 0x10);
  r.host.set_param(0, Reg::MAX_SPEED, test::max_speed_from_steps_per_s(80));
  r.host.move(0, false, 12'800);
  ASSERT_TRUE(r.wait_idle());
  EXPECT_EQ(r.axis().lost_steps(), 0);
  r.host.move(0, true, 12'800);
  ASSERT_TRUE(r.wait_idle());
  EXPECT_GE(r.axis().lost_steps(), 12'800 - 4 * kStep) << "lost from the first tick on";
  EXPECT_EQ(r.axis().lost_steps() % (4 * kStep), 0);
}

TEST(AxisPhysics, AHardStopKeepsTheRotorThereWhileAbsPosCountsOn) {
  AxisSpec spec;
  spec.has_upper_stop = true;
  spec.upper_stop = 50 * kStep;
  Rig r(spec);
  r.host.move(0, true, 100 * 128);
  ASSERT_TRUE(r.wait_idle());
  EXPECT_EQ(r.chip().position(), 100 * 128);
  EXPECT_LE(r.axis().true_position(), 50 * kStep);
  EXPECT_GE(r.axis().true_position(), 48 * kStep) << "pulled in within two full steps of the stop";
  EXPECT_EQ((r.chip().position() - r.axis().true_position() - r.axis().lost_steps()), 0);
}

TEST(AxisPhysics, ABlockedRotorDrawsMoreCurrentThanStallThAndLatchesStepLossAAndB) {
  AxisSpec spec;
  spec.has_lower_stop = true;
  spec.lower_stop = 0;
  spec.start_position = 10 * kStep;
  Rig r(spec);
  r.host.set_param(0, Reg::KVAL_RUN, 0x10);
  r.host.set_param(0, Reg::KVAL_ACC, 0x10);
  r.host.set_param(0, Reg::KVAL_DEC, 0x10);
  r.host.set_param(0, Reg::STALL_TH, 18);  // 0.59 A: above the following rotor's 0.5 A, below the blocked one's
  r.host.run(0, false, test::spd_from_steps_per_s(100));
  r.wait_ms(50);
  EXPECT_TRUE(r.chip().flag_pin()) << "running free: no stall";
  EXPECT_EQ(r.host.get_status(0) & (kStepLossAN | kStepLossBN), kStepLossAN | kStepLossBN);
  r.wait_ms(100);
  EXPECT_TRUE(r.axis().at_stop());
  EXPECT_GT(r.axis().phase_current_mA(), 594u);
  EXPECT_FALSE(r.chip().flag_pin());
  EXPECT_EQ(r.host.get_status(0) & (kStepLossAN | kStepLossBN), 0) << "both active low";
  EXPECT_EQ(r.host.get_status(0) & (kStepLossAN | kStepLossBN), 0) << "still blocked: the condition stays";
  r.host.hard_stop(0);
  r.host.get_status(0);
  EXPECT_EQ(r.host.get_status(0) & (kStepLossAN | kStepLossBN), kStepLossAN | kStepLossBN) << "cleared once stopped";
  EXPECT_TRUE(r.chip().flag_pin());
}

TEST(AxisPhysics, TheOvercurrentComparatorLatchesOcdAndOcSdDisablesTheBridges) {
  Rig r(AxisSpec{});
  r.host.set_param(0, Reg::OCD_TH, 2);  // 1.125 A, below the 1.28 A holding current
  r.host.hard_stop(0);                  // bridges on: holding current flows
  EXPECT_TRUE(r.chip().hiz()) << "OC_SD (CONFIG reset) shut the bridges down";
  EXPECT_FALSE(r.chip().flag_pin());
  EXPECT_EQ(r.host.get_status(0) & kOcdN, 0);
  EXPECT_EQ(r.host.get_status(0) & kOcdN, kOcdN) << "released: no current in HiZ";
}

TEST(AxisPhysics, TheL6480DetectsAStallFromTheMosfetDrainSourceVoltage) {
  AxisSpec spec;
  spec.has_lower_stop = true;
  spec.start_position = 5 * kStep;
  spec.supply.rds_on_mohm = 100;
  Rig r(spec, l6480());
  r.host.set_param(0, Reg::KVAL_RUN, 0x10);
  r.host.set_param(0, Reg::KVAL_ACC, 0x10);
  r.host.set_param(0, Reg::KVAL_DEC, 0x10);
  r.host.set_param(0, Reg::STALL_TH, 1);  // 62.5 mV: 0.625 A through 100 mΩ
  r.host.run(0, false, test::spd_from_steps_per_s(100));
  r.wait_ms(20);
  EXPECT_TRUE(r.chip().flag_pin());
  r.wait_ms(100);
  EXPECT_TRUE(r.axis().at_stop());
  const std::uint16_t stall_bits = (1u << 14) | (1u << 15);
  EXPECT_EQ(r.host.get_status(0) & stall_bits, 0) << "STALL_A and STALL_B, active low";
  EXPECT_FALSE(r.chip().flag_pin());
}

TEST(AxisPhysics, TheL6472LosesStepsAtAHardStopWithoutAnyFlag) {
  AxisSpec spec;
  spec.has_lower_stop = true;
  spec.start_position = 5 * kStep;
  Rig r(spec, l6472());
  r.host.run(0, false, test::spd_from_steps_per_s(100));
  r.wait_ms(200);
  EXPECT_TRUE(r.axis().at_stop());
  EXPECT_LT(r.chip().position(), -10 * 16) << "ABS_POS counts on (1/16 step: the L6472's finest)";
  EXPECT_LT(r.axis().lost_steps(), -8 * kStep) << "commanded minus true travel: negative going in reverse";
  EXPECT_TRUE(r.chip().flag_pin());
  EXPECT_EQ(r.host.get_status(0) & (kStepLossAN | kStepLossBN), 0) << "the L6472 has no stall bits";
}

TEST(AxisPhysics, ASwitchDrivesSwAtTheExactTickTheRotorGetsThere) {
  AxisSpec spec;
  SwitchSpec sw;
  sw.position = 640;
  sw.above = true;
  sw.hysteresis = 16;
  spec.switches.push_back(sw);
  Rig r(spec);
  r.host.hard_hiz(0);
  r.host.set_param(0, Reg::CONFIG, 0x2E88 | 0x10);  // SW_MODE = 1: no HardStop, just SW_EVN
  r.host.run(0, true, test::spd_from_steps_per_s(100));
  // 640 microsteps at 1/128 = 5 full steps; ramp from 0 at 2008 step/s².
  while (r.chip().sw_pin()) r.chain.advance_to(r.chain.now() + 1);
  EXPECT_EQ(r.axis().true_position(), 640);
  EXPECT_EQ(r.chip().position(), 640);
  r.host.run(0, false, test::spd_from_steps_per_s(100));
  while (!r.chip().sw_pin()) r.chain.advance_to(r.chain.now() + 1);
  EXPECT_EQ(r.axis().true_position(), 640 - 16 - 1) << "released past the hysteresis";
}

TEST(AxisPhysics, ANormallyClosedSwitchWithBounceChattersThenSettles) {
  AxisSpec spec;
  SwitchSpec sw;
  sw.position = 0;
  sw.normally_closed = true;
  sw.bounce_count = 2;
  sw.bounce_ticks = 400;  // 100 µs
  spec.switches.push_back(sw);
  spec.start_position = 3 * kStep;
  Rig r(spec);
  EXPECT_FALSE(r.chip().sw_pin()) << "not actuated: a normally closed contact pulls SW low";
  r.host.hard_hiz(0);
  r.host.set_param(0, Reg::CONFIG, 0x2E88 | 0x10);
  r.host.run(0, false, test::spd_from_steps_per_s(50));
  while (!r.chip().sw_pin()) r.chain.advance_to(r.chain.now() + 1);
  const Tick opened = r.chain.now();
  r.host.hard_stop(0);
  std::vector<Tick> edges;
  bool level = true;
  for (Tick t = opened + 1; t < opened + 4000; ++t) {
    r.chain.advance_to(t);
    if (r.chip().sw_pin() != level) {
      level = !level;
      edges.push_back(t - opened);
    }
  }
  EXPECT_EQ(edges, (std::vector<Tick>{400, 800, 1200, 1600}));
  EXPECT_TRUE(level) << "settled open";
}

TEST(AxisPhysics, NextEventTickIncludesAPendingBounceEdgeWhileTheMotorStands) {
  AxisSpec spec;
  SwitchSpec sw;
  sw.position = 0;
  sw.bounce_count = 1;
  sw.bounce_ticks = 1000;
  spec.switches.push_back(sw);
  spec.start_position = 2 * kStep;
  Rig r(spec);
  r.host.hard_hiz(0);
  r.host.set_param(0, Reg::CONFIG, 0x2E88 | 0x10);
  r.host.run(0, false, test::spd_from_steps_per_s(50));
  while (r.chip().sw_pin()) r.chain.advance_to(r.chain.now() + 1);
  const Tick closed = r.chain.now();
  r.host.hard_stop(0);
  EXPECT_EQ(r.chip().next_event_tick(), closed + 1000) << "the contact reverts once, 1000 ticks later";
  r.chain.advance_to(closed + 1000);
  EXPECT_TRUE(r.chip().sw_pin());
  EXPECT_EQ(r.chip().next_event_tick(), closed + 2000);
  r.chain.advance_to(closed + 2000);
  EXPECT_FALSE(r.chip().sw_pin());
  EXPECT_EQ(r.chip().next_event_tick(), kNever);
}

TEST(AxisPhysics, CopyingAChipCopiesItsAxisAndTheCopiesGoTheirOwnWays) {
  Chip a;
  a.attach_axis(AxisSpec{});
  a.on_byte(0xD0);  // GetStatus: clear the power-up flag
  Chip b = a;
  for (std::uint8_t x : {0x51, 0x00, 0x10, 0x00}) b.on_byte(x);  // Run forward
  a.advance_to(ticks_from_ms(100));
  b.advance_to(ticks_from_ms(100));
  EXPECT_EQ(a.axis()->true_position(), 0);
  EXPECT_GT(b.axis()->true_position(), 0);
  EXPECT_EQ(b.axis()->true_position(), b.position());
}

}  // namespace
}  // namespace l6470emu
