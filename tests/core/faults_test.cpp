// Protections: undervoltage, thermal warning and shutdown, overcurrent (with and
// without OC_SD) and stall; how their STATUS flags latch and clear, how they hold
// the bridges in HiZ and refuse motion (spec §4.2, §6.5; datasheet §6.9-6.11;
// docs/chip-model.md "Faults"). Not the FLAG pin masking (pins_test).
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/chip.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;


constexpr std::uint32_t kConfigReset = 0x2E88;  // OC_SD = 1
constexpr std::uint32_t kOcSd = 1u << 7;

struct Rig : test::OneChip {
  Rig() { host.get_status(0); }  // past the power-up UVLO flag
  ChainHost& h() { return host; }
  std::uint16_t status() { return static_cast<std::uint16_t>(host.get_param(0, Reg::STATUS)); }
  std::uint16_t get_status() { return host.get_status(0); }
  std::int32_t abs_pos() { return sign_extend(host.get_param(0, Reg::ABS_POS), 22); }
  std::uint32_t speed() { return host.get_param(0, Reg::SPEED); }
  bool busy() { return !chip().busy_sync_pin(); }
  void wait_s(double s) { host.wait(static_cast<Tick>(s * kTicksPerSecond)); }
  void run_at_speed() {
    host.run(0, true, test::spd_from_steps_per_s(400));
    wait_s(0.3);
  }
  bool moving() {
    const std::int32_t p = chip().position();
    host.wait(ticks_from_ms(2));
    return chip().position() != p;
  }
};

// ---- undervoltage ----------------------------------------------------------------

TEST(Faults, UndervoltageStopsTheMotorAndDisablesTheBridges) {
  Rig r;
  r.run_at_speed();
  r.chip().set_undervoltage(true);
  const auto s = r.status();
  EXPECT_FALSE(s & kUvloN);
  EXPECT_TRUE(s & kHiZ);
  EXPECT_TRUE(s & kBusyN);
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_EQ(r.speed(), 0u);
  EXPECT_FALSE(r.moving());
}

TEST(Faults, UvloStaysActiveAfterGetStatusWhileTheSupplyIsLow) {
  Rig r;
  r.chip().set_undervoltage(true);
  EXPECT_FALSE(r.get_status() & kUvloN);
  EXPECT_FALSE(r.get_status() & kUvloN) << "the condition is still present";
  r.chip().set_undervoltage(false);
  EXPECT_FALSE(r.status() & kUvloN) << "latched until GetStatus";
  EXPECT_FALSE(r.get_status() & kUvloN) << "GetStatus answers with the latched value";
  EXPECT_TRUE(r.get_status() & kUvloN);
}

TEST(Faults, MotionCanResumeOnceTheSupplyIsBack) {
  Rig r;
  r.chip().set_undervoltage(true);
  r.chip().set_undervoltage(false);
  r.get_status();
  r.h().run(0, true, test::spd_from_steps_per_s(300));
  const auto s = r.get_status();
  EXPECT_FALSE(s & kNotPerf);
  EXPECT_FALSE(s & kHiZ);
  r.wait_s(0.2);
  EXPECT_TRUE(r.moving());
}

// ---- thermal --------------------------------------------------------------------------

TEST(Faults, ThermalWarningOnlyRaisesTheFlag) {
  Rig r;
  r.run_at_speed();
  r.chip().set_thermal(Thermal::warning);
  const auto s = r.status();
  EXPECT_FALSE(s & kThWrnN);
  EXPECT_TRUE(s & kThSdN);
  EXPECT_FALSE(s & kHiZ);
  EXPECT_TRUE(r.moving());
  EXPECT_EQ(r.speed(), test::spd_from_steps_per_s(400));
}

TEST(Faults, ThermalWarningIsLatchedUntilGetStatusAfterCooling) {
  Rig r;
  r.chip().set_thermal(Thermal::warning);
  EXPECT_FALSE(r.get_status() & kThWrnN);
  EXPECT_FALSE(r.get_status() & kThWrnN) << "still hot";
  r.chip().set_thermal(Thermal::normal);
  EXPECT_FALSE(r.status() & kThWrnN);
  EXPECT_FALSE(r.get_status() & kThWrnN);
  EXPECT_TRUE(r.get_status() & kThWrnN);
}

TEST(Faults, ThermalShutdownStopsTheMotorAndDisablesTheBridges) {
  Rig r;
  r.run_at_speed();
  r.chip().set_thermal(Thermal::bridge_shutdown);
  const auto s = r.status();
  EXPECT_FALSE(s & kThSdN);
  EXPECT_FALSE(s & kThWrnN) << "beyond the shutdown level is beyond the warning level";
  EXPECT_TRUE(s & kHiZ);
  EXPECT_TRUE(s & kBusyN);
  EXPECT_EQ(r.speed(), 0u);
  EXPECT_FALSE(r.moving());
}

TEST(Faults, BridgesStayOffAfterThermalShutdownUntilAMotionCommand) {
  Rig r;
  r.run_at_speed();
  r.chip().set_thermal(Thermal::bridge_shutdown);
  r.chip().set_thermal(Thermal::normal);
  r.wait_s(0.01);
  auto s = r.status();
  EXPECT_TRUE(s & kHiZ) << "cooling alone does not re-enable the bridges";
  EXPECT_FALSE(s & kThSdN) << "TH_SD latched until GetStatus";
  EXPECT_FALSE(r.moving());
  r.h().hard_stop(0);  // any motion command, HardStop included
  s = r.get_status();
  EXPECT_FALSE(s & kHiZ);
  EXPECT_FALSE(s & kNotPerf);
  EXPECT_TRUE(r.get_status() & kThSdN);
}

// Datasheet §6.11 (spec §6.5): "Thermal shutdown condition only expires when the
// temperature goes below the thermal warning threshold"; docs/chip-model.md: bridges
// stay off until a motion command after the temperature is back below the warning level.
// (This test caught a model bug at 07ea145 — cooling from bridge_shutdown to warning
// ended the shutdown at once; fixed in 3bc7068.)
TEST(Faults, ThermalShutdownHoldsUntilTheDieIsBelowTheWarningLevel) {
  Rig r;
  r.chip().set_thermal(Thermal::bridge_shutdown);
  r.chip().set_thermal(Thermal::warning);  // cooler, but still above the warning threshold
  r.get_status();
  r.h().run(0, true, test::spd_from_steps_per_s(300));
  auto s = r.get_status();
  EXPECT_TRUE(s & kNotPerf) << "still in thermal shutdown";
  EXPECT_TRUE(s & kHiZ);
  EXPECT_FALSE(s & kThSdN) << "TH_SD still active while above Tj(WRN)";
  r.chip().set_thermal(Thermal::normal);
  r.get_status();
  r.h().run(0, true, test::spd_from_steps_per_s(300));
  s = r.get_status();
  EXPECT_FALSE(s & kNotPerf);
  EXPECT_FALSE(s & kHiZ);
}

TEST(Faults, ThermalShutdownFlagStaysWhileTheDieIsHot) {
  Rig r;
  r.chip().set_thermal(Thermal::bridge_shutdown);
  EXPECT_FALSE(r.get_status() & kThSdN);
  EXPECT_FALSE(r.get_status() & kThSdN);
  r.chip().set_thermal(Thermal::normal);
  EXPECT_FALSE(r.get_status() & kThSdN);
  const auto s = r.get_status();
  EXPECT_TRUE(s & kThSdN);
  EXPECT_TRUE(s & kThWrnN);
}

// ---- overcurrent ---------------------------------------------------------------------------

TEST(Faults, OvercurrentWithOcSdDisablesTheBridges) {
  Rig r;
  ASSERT_EQ(r.h().get_param(0, Reg::CONFIG) & kOcSd, kOcSd);
  r.run_at_speed();
  r.chip().set_overcurrent(true);
  const auto s = r.status();
  EXPECT_FALSE(s & kOcdN);
  EXPECT_TRUE(s & kHiZ);
  EXPECT_TRUE(s & kBusyN);
  EXPECT_EQ(r.speed(), 0u);
  EXPECT_FALSE(r.moving());
}

TEST(Faults, OcdShutdownHoldsUntilGetStatusAfterTheOvercurrentHasGone) {
  Rig r;
  r.run_at_speed();
  r.chip().set_overcurrent(true);
  EXPECT_FALSE(r.get_status() & kOcdN);  // GetStatus during the overcurrent releases nothing
  r.h().run(0, true, test::spd_from_steps_per_s(300));
  auto s = r.get_status();
  EXPECT_TRUE(s & kNotPerf);
  EXPECT_TRUE(s & kHiZ);
  EXPECT_FALSE(s & kOcdN);

  r.chip().set_overcurrent(false);
  r.h().run(0, true, test::spd_from_steps_per_s(300));  // no GetStatus yet since it ended
  s = r.status();
  EXPECT_TRUE(s & kNotPerf) << "bridges cannot be re-enabled before GetStatus releases OCD";
  EXPECT_TRUE(s & kHiZ);
  EXPECT_FALSE(r.moving());

  s = r.get_status();
  EXPECT_FALSE(s & kOcdN);
  s = r.get_status();
  EXPECT_TRUE(s & kOcdN);
  EXPECT_TRUE(s & kHiZ) << "GetStatus does not clear HiZ";
  r.h().run(0, true, test::spd_from_steps_per_s(300));
  s = r.get_status();
  EXPECT_FALSE(s & kNotPerf);
  EXPECT_FALSE(s & kHiZ);
  r.wait_s(0.2);
  EXPECT_TRUE(r.moving());
}

TEST(Faults, OvercurrentWithoutOcSdOnlyRaisesTheFlag) {
  Rig r;
  r.h().set_param(0, Reg::CONFIG, kConfigReset & ~kOcSd);  // WH: still HiZ after power-up
  ASSERT_EQ(r.h().get_param(0, Reg::CONFIG), kConfigReset & ~kOcSd);
  r.run_at_speed();
  r.chip().set_overcurrent(true);
  auto s = r.status();
  EXPECT_FALSE(s & kOcdN);
  EXPECT_FALSE(s & kHiZ);
  EXPECT_TRUE(r.moving());
  EXPECT_FALSE(r.get_status() & kOcdN);
  EXPECT_FALSE(r.get_status() & kOcdN) << "still over the threshold";
  r.chip().set_overcurrent(false);
  EXPECT_FALSE(r.get_status() & kOcdN);
  EXPECT_TRUE(r.get_status() & kOcdN);
  EXPECT_TRUE(r.moving());
}

// ---- stall ----------------------------------------------------------------------------------

TEST(Faults, StallOnBridgeALatchesStepLossAOnly) {
  Rig r;
  r.run_at_speed();
  r.chip().set_stall(Bridge::A, true);
  auto s = r.status();
  EXPECT_FALSE(s & kStepLossAN);
  EXPECT_TRUE(s & kStepLossBN);
  EXPECT_FALSE(s & kHiZ);
  EXPECT_TRUE(r.moving()) << "a stall only raises the flag";
  EXPECT_FALSE(r.get_status() & kStepLossAN);
  EXPECT_FALSE(r.get_status() & kStepLossAN) << "still stalling";
  r.chip().set_stall(Bridge::A, false);
  EXPECT_FALSE(r.status() & kStepLossAN);
  EXPECT_FALSE(r.get_status() & kStepLossAN);
  EXPECT_TRUE(r.get_status() & kStepLossAN);
}

TEST(Faults, StallOnBridgeBLatchesStepLossBOnly) {
  Rig r;
  r.run_at_speed();
  r.chip().set_stall(Bridge::B, true);
  r.chip().set_stall(Bridge::B, false);  // a short stall
  auto s = r.status();
  EXPECT_FALSE(s & kStepLossBN);
  EXPECT_TRUE(s & kStepLossAN);
  EXPECT_TRUE(r.moving());
  EXPECT_FALSE(r.get_status() & kStepLossBN);
  EXPECT_TRUE(r.get_status() & kStepLossBN);
}

// ---- latching in general -----------------------------------------------------------------

TEST(Faults, GetParamStatusClearsNoLatchedFault) {
  Rig r;
  r.chip().set_thermal(Thermal::warning);
  r.chip().set_thermal(Thermal::normal);
  r.chip().set_stall(Bridge::A, true);
  r.chip().set_stall(Bridge::A, false);
  r.chip().set_overcurrent(true);
  r.chip().set_overcurrent(false);
  for (int i = 0; i < 3; ++i) {
    const auto s = r.status();
    EXPECT_FALSE(s & kThWrnN);
    EXPECT_FALSE(s & kStepLossAN);
    EXPECT_FALSE(s & kOcdN);
  }
  r.get_status();
  const auto s = r.status();
  EXPECT_TRUE(s & kThWrnN);
  EXPECT_TRUE(s & kStepLossAN);
  EXPECT_TRUE(s & kOcdN);
}

TEST(Faults, SeveralFaultsLatchTogetherAndClearTogether) {
  Rig r;
  r.chip().set_undervoltage(true);
  r.chip().set_thermal(Thermal::warning);
  r.chip().set_stall(Bridge::B, true);
  r.chip().set_undervoltage(false);
  r.chip().set_thermal(Thermal::normal);
  r.chip().set_stall(Bridge::B, false);
  const auto s = r.get_status();
  EXPECT_EQ(s & (kUvloN | kThWrnN | kStepLossBN), 0);
  EXPECT_EQ(r.get_status(), 0x7E03) << "all released, bridges still HiZ";
}

// ---- step-clock mode and refused commands ----------------------------------------------------

TEST(Faults, FaultsForcingHiZDoNotLeaveStepClockMode) {
  const std::vector<std::pair<const char*, std::function<void(Chip&)>>> faults = {
      {"thermal shutdown", [](Chip& c) { c.set_thermal(Thermal::bridge_shutdown); }},
      {"overcurrent", [](Chip& c) { c.set_overcurrent(true); }},
      {"undervoltage", [](Chip& c) { c.set_undervoltage(true); }},
  };
  for (const auto& [name, raise] : faults) {
    SCOPED_TRACE(name);
    Rig r;
    r.h().step_clock(0, true);
    ASSERT_TRUE(r.status() & kSckMod);
    raise(r.chip());
    const auto s = r.status();
    EXPECT_TRUE(s & kSckMod);
    EXPECT_TRUE(s & kHiZ);
    EXPECT_EQ(mot(s), kStopped);
  }
}

using Command = std::function<void(ChainHost&)>;

std::vector<std::pair<const char*, Command>> motion_commands() {
  const std::uint32_t spd = test::spd_from_steps_per_s(300);
  return {
      {"Run", [spd](ChainHost& h) { h.run(0, true, spd); }},
      {"Move", [](ChainHost& h) { h.move(0, true, 1000); }},
      {"GoTo", [](ChainHost& h) { h.go_to(0, 1000); }},
      {"GoTo_DIR", [](ChainHost& h) { h.go_to_dir(0, false, 1000); }},
      {"GoHome", [](ChainHost& h) { h.go_home(0); }},
      {"GoMark", [](ChainHost& h) { h.go_mark(0); }},
      {"GoUntil", [spd](ChainHost& h) { h.go_until(0, false, true, spd); }},
      {"ReleaseSW", [](ChainHost& h) { h.release_sw(0, false, true); }},
  };
}

TEST(Faults, MotionCommandsAreRefusedWhileAFaultHoldsTheBridgesInHiZ) {
  const std::vector<std::pair<const char*, std::function<void(Chip&)>>> faults = {
      {"thermal shutdown", [](Chip& c) { c.set_thermal(Thermal::bridge_shutdown); }},
      {"overcurrent with OC_SD", [](Chip& c) { c.set_overcurrent(true); }},
      {"undervoltage", [](Chip& c) { c.set_undervoltage(true); }},
  };
  for (const auto& [fault, raise] : faults) {
    for (const auto& [name, command] : motion_commands()) {
      SCOPED_TRACE(std::string(fault) + " / " + name);
      Rig r;
      r.h().set_param(0, Reg::MARK, 500);
      r.h().set_param(0, Reg::ABS_POS, 100);
      raise(r.chip());
      r.get_status();
      command(r.h());
      const auto s = r.get_status();
      EXPECT_TRUE(s & kNotPerf);
      EXPECT_TRUE(s & kHiZ);
      EXPECT_TRUE(s & kBusyN);
      r.wait_s(0.01);
      EXPECT_EQ(r.abs_pos(), 100);
      EXPECT_EQ(r.speed(), 0u);
    }
  }
}

TEST(Faults, StopCommandsDuringAFaultJustStopWithoutLeavingHiZ) {
  Rig r;
  r.chip().set_thermal(Thermal::bridge_shutdown);
  r.get_status();
  for (auto stop : {&ChainHost::soft_stop, &ChainHost::hard_stop, &ChainHost::soft_hiz, &ChainHost::hard_hiz}) {
    (r.h().*stop)(0);
    const auto s = r.get_status();
    EXPECT_FALSE(s & kNotPerf);
    EXPECT_TRUE(s & kHiZ);
  }
}

TEST(Faults, SwitchInterruptDoesNotEnableTheBridgesDuringAFault) {
  Rig r;
  r.chip().set_thermal(Thermal::bridge_shutdown);
  r.chip().set_sw_pin(false);  // SW_MODE 0: a HardStop interrupt
  EXPECT_TRUE(r.status() & kHiZ);
}

}  // namespace
}  // namespace l6470emu
