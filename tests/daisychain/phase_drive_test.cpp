// phase_drive (daisychain/phase_drive.hpp): the sine generator's two levels as EL_POS walks it —
// full steps at odd multiples of 45° (two phases on), half steps adding the one-phase-on points,
// the amplitude of the motion phase's KVAL (TVAL in current mode), nothing in high impedance.
#include <gtest/gtest.h>

#include <set>
#include <utility>

#include "daisychain/host.hpp"
#include "daisychain/phase_drive.hpp"

namespace l6470emu {
namespace {

TEST(PhaseDrive, FullStepsAreTheFourTwoPhaseOnPoints) {
  EXPECT_EQ(phase_levels(0, 1000), (PhaseDrive{707, 707}));
  EXPECT_EQ(phase_levels(128, 1000), (PhaseDrive{707, -707}));
  EXPECT_EQ(phase_levels(256, 1000), (PhaseDrive{-707, -707}));
  EXPECT_EQ(phase_levels(384, 1000), (PhaseDrive{-707, 707}));
  EXPECT_EQ(phase_levels(512, 1000), phase_levels(0, 1000)) << "EL_POS is 9 bits";
}

TEST(PhaseDrive, HalfStepsAddTheOnePhaseOnPoints) {
  EXPECT_EQ(phase_levels(64, 1000), (PhaseDrive{1000, 0}));
  EXPECT_EQ(phase_levels(192, 1000), (PhaseDrive{0, -1000}));
  EXPECT_EQ(phase_levels(320, 1000), (PhaseDrive{-1000, 0}));
  EXPECT_EQ(phase_levels(448, 1000), (PhaseDrive{0, 1000}));
}

TEST(PhaseDrive, MicrostepsFollowTheSineAtTheAmplitude) {
  for (unsigned el = 0; el < 512; ++el) {
    const PhaseDrive d = phase_levels(static_cast<std::uint16_t>(el), 500);
    const int r2 = d.coil_a * d.coil_a + d.coil_b * d.coil_b;
    EXPECT_NEAR(r2, 250000, 1000) << "EL_POS " << el;  // on the circle of radius 500
  }
}

TEST(PhaseDrive, NothingWhileTheBridgesAreInHighImpedance) {
  Chain chain(1);
  EXPECT_EQ(phase_drive(chain.chip(0)), PhaseDrive{}) << "power-up: HiZ";
}

TEST(PhaseDrive, HoldAndRunUseTheirKval) {
  Chain chain(1);
  ChainHost host(chain);
  host.get_status(0);
  host.set_param(0, Reg::KVAL_HOLD, 64);  // 25 %
  host.set_param(0, Reg::KVAL_RUN, 128);  // 50 %
  host.set_param(0, Reg::KVAL_ACC, 128);
  host.set_param(0, Reg::KVAL_DEC, 128);
  host.hard_stop(0);                      // bridges on, stopped: KVAL_HOLD
  EXPECT_EQ(phase_drive(chain.chip(0)), phase_levels(0, 250));
  host.run(0, true, 0x4189);              // 250 step/s
  host.wait_ms(500);
  const Chip& c = chain.chip(0);
  EXPECT_EQ(mot_status(c.motion(), c.profile()), MotStatus::constant_speed);
  EXPECT_EQ(phase_drive(c), phase_levels(c.motion().el_pos, 500));
}

TEST(PhaseDrive, AFullStepMoveWalksTheFourPoints) {
  Chain chain(1);
  ChainHost host(chain);
  host.get_status(0);
  host.set_param(0, Reg::STEP_MODE, 0);  // full step: EL_POS moves by 128
  host.hard_stop(0);
  host.move(0, true, 8);
  std::set<std::pair<int, int>> seen;
  for (int i = 0; i < 400; ++i) {
    host.wait(ticks_from_us(500));
    const PhaseDrive d = phase_drive(chain.chip(0));
    seen.insert({d.coil_a > 0 ? 1 : -1, d.coil_b > 0 ? 1 : -1});
    EXPECT_EQ(std::abs(d.coil_a), std::abs(d.coil_b)) << "two phases on, equal";
  }
  EXPECT_EQ(seen.size(), 4u);
}

}  // namespace
}  // namespace l6470emu
