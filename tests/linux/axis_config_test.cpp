// The axis clause of the board description (axis.K=...): what it builds, one test per error
// it reports, the description reading back as the same axes, and `ctl axis` / `ctl status`
// showing the true position next to ABS_POS and changing the load at runtime.
#include <gtest/gtest.h>

#include "core/axis_text.hpp"
#include "board/board_config.hpp"
#include "daisychain/host.hpp"
#include "linux/device_board.hpp"
#include "linux/log.hpp"
#include "linux/serve/control.hpp"

namespace l6470emu {
namespace {

std::string error_of(const std::string& text) {
  const ParseResult r = parse_board_config(text, "board.conf");
  EXPECT_FALSE(r.config) << text;
  return r.error.message;
}

TEST(AxisConfig, AnAxisClauseDescribesMotorLoadStopsAndSwitchesOfOneChip) {
  const ParseResult r = parse_board_config(
      "chips=3xL6470 axis.1=steps=400,torque=0.5,current=2,r=1.2,l=3.1,rotor=82,load=120.5,friction=0.02,force=-0.1,"
      "vs=24,rds=0.05,rsense=0.1,pullin=150,stops=-1280..256000,start=12800,"
      "switch=home@0:below:no:hyst=8,switch=end@250000:above:nc:bounce=3/50",
      "board.conf");
  ASSERT_TRUE(r.config) << r.error.message;
  const ChainConfig& c = r.config->chains.at(0);
  ASSERT_EQ(c.axes.size(), 1u);
  EXPECT_EQ(c.axes[0].first, 1u);
  const AxisSpec& a = c.axes[0].second;
  EXPECT_EQ(a.motor.steps_per_rev, 400u);
  EXPECT_EQ(a.motor.holding_torque_uNm, 500'000u);
  EXPECT_EQ(a.motor.rated_current_mA, 2'000u);
  EXPECT_EQ(a.motor.phase_resistance_mohm, 1'200u);
  EXPECT_EQ(a.motor.phase_inductance_uH, 3'100u);
  EXPECT_EQ(a.motor.rotor_inertia_g_mm2, 8'200u);
  EXPECT_EQ(a.load.inertia_g_mm2, 12'050u);
  EXPECT_EQ(a.load.friction_uNm, 20'000u);
  EXPECT_EQ(a.load.force_uNm, -100'000);
  EXPECT_EQ(a.supply.supply_mV, 24'000u);
  EXPECT_EQ(a.supply.rds_on_mohm, 50u);
  EXPECT_EQ(a.supply.sense_mohm, 100u);
  EXPECT_EQ(a.pull_in_speed_steps_per_s, 150u);
  EXPECT_TRUE(a.has_lower_stop && a.has_upper_stop);
  EXPECT_EQ(a.lower_stop, -1280);
  EXPECT_EQ(a.upper_stop, 256000);
  EXPECT_EQ(a.start_position, 12800);
  ASSERT_EQ(a.switches.size(), 2u);
  EXPECT_EQ(a.switches[0].name, "home");
  EXPECT_EQ(a.switches[0].hysteresis, 8);
  EXPECT_FALSE(a.switches[0].above);
  EXPECT_TRUE(a.switches[1].above);
  EXPECT_TRUE(a.switches[1].normally_closed);
  EXPECT_EQ(a.switches[1].bounce_count, 3u);
  EXPECT_EQ(a.switches[1].bounce_ticks, 200u);
}

TEST(AxisConfig, DefaultIsACommonNema17WithNothingAttached) {
  const ParseResult r = parse_board_config("chips=L6470 axis.0=default", "t");
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_EQ(r.config->chains[0].axes.at(0).second, AxisSpec{});
}

TEST(AxisConfig, TheDescriptionReadsBackAsTheSameAxes) {
  const ParseResult r = parse_board_config(
      "chips=2xL6480 axis.1=torque=0.3,force=-0.05,stops=..5000,switch=a@-7:above:hyst=2,switch=b@9:nc:bounce=1/3 "
      "axis.0=default",
      "t");
  ASSERT_TRUE(r.config) << r.error.message;
  const std::string d = describe_board_config(*r.config);
  EXPECT_NE(d.find(" axis.0=default axis.1=torque=0.3,force=-0.05,stops=..5000,"), std::string::npos) << d;
  const ParseResult back = parse_board_config(d, "description");
  ASSERT_TRUE(back.config) << back.error.message;
  EXPECT_EQ(back.config->chains[0].axes, r.config->chains[0].axes);
}

TEST(AxisConfig, AnAxisForAChipTheChainDoesNotHaveSaysHowManyItHas) {
  EXPECT_EQ(error_of("chips=2xL6470 axis.2=default"),
            "l6470emu: config board.conf, clause 1: axis.2= names chip 2 but the chain has 2 chips (0 to 1)");
}

TEST(AxisConfig, AnAxisKeyWithoutAChipNumberIsRefused) {
  EXPECT_NE(error_of("chips=L6470 axis.x=default").find("axis key 'axis.x' needs a chip number"), std::string::npos);
}

TEST(AxisConfig, AnAxisOutsideAChainClauseIsRefused) {
  EXPECT_NE(error_of("chips=L6470; axis.0=default").find("clause 2: axis.0= describes a chip of a chain"),
            std::string::npos);
}

TEST(AxisConfig, TheSameAxisTwiceInAClauseIsRefused) {
  EXPECT_NE(error_of("chips=L6470 axis.0=default axis.0=default").find("axis.0= is given twice"), std::string::npos);
}

TEST(AxisConfig, AnEmptyAxisValueIsRefused) {
  EXPECT_NE(error_of("chips=L6470 axis.0=").find("axis.0= has no value"), std::string::npos);
}

TEST(AxisConfig, EveryItemErrorNamesTheItemAndWhatItTakes) {
  const std::pair<const char*, const char*> cases[] = {
      {"torque=-1", "torque= must be 0.000001 to 1000 (N·m holding torque, at most 6 decimals), not '-1'"},
      {"current=1.2345", "current= must be 0.001 to 100 (A rated phase current, at most 3 decimals), not '1.2345'"},
      {"steps=198", "steps= must be a multiple of 4"},
      {"steps=x", "steps= must be 4 to 100000"},
      {"vs=0.5", "vs= must be 1 to 100"},
      {"r=0", "r= must be 0.001 to 1000"},
      {"pullin=20000", "pullin= must be 0 to 15625"},
      {"stops=5", "stops= is LO..HI"},
      {"stops=..", "stops=.. names no stop"},
      {"stops=9..1", "stops= '9..1': the lower stop is above the upper one"},
      {"stops=a..1", "stops= lower stop 'a'"},
      {"stops=0..1,start=5", "start=5 lies beyond a hard stop"},
      {"start=1.5", "start= must be a whole number"},
      {"switch=home", "switch='home' needs NAME@POSITION"},
      {"switch=h%@1", "switch name 'h%' may hold"},
      {"switch=h@x", "switch h: position 'x'"},
      {"switch=h@1:sideways", "switch h: unknown part 'sideways'"},
      {"switch=h@1:hyst=-1", "switch h: hyst= must be 0 to 1048576"},
      {"switch=h@1:bounce=3", "switch h: bounce= is COUNT/MICROSECONDS"},
      {"friction=1,friction=2", "friction= is given twice"},
      {"colour=blue", "unknown item 'colour'"},
      {"torque", "item 'torque' is not NAME=VALUE"},
      {"torque=1,,r=1", "empty item"},
      {"torque=", "torque= has no value"},
  };
  for (const auto& [items, expected] : cases) {
    const std::string e = error_of(std::string("chips=L6470 axis.0=") + items);
    EXPECT_NE(e.find(std::string("clause 1: axis.0: ") + expected), std::string::npos) << items << "\n" << e;
  }
}

TEST(AxisConfig, AMisspeltItemOrAxisKeyIsNamedWithItsNearMiss) {
  EXPECT_NE(error_of("chips=L6470 axis.0=torqe=1").find("unknown item 'torqe': did you mean torque=?"), std::string::npos);
  EXPECT_NE(error_of("chips=L6470 axis.0=swich:100").find("item 'swich:100' is not NAME=VALUE (did you mean switch=...?)"),
            std::string::npos);
  const std::string key = error_of("chips=L6470 axsi.0=steps=200");
  EXPECT_NE(key.find("unknown key 'axsi.0': did you mean axis.0=?"), std::string::npos) << key;
  EXPECT_NE(key.find(", axis.K;"), std::string::npos) << "the keys listed name axis.K: " << key;
}

TEST(AxisConfig, RuntimeLoadChangesAcceptOnlyLoadItems) {
  LoadSpec load;
  EXPECT_EQ(parse_axis_load("friction=0.1,force=-0.02,load=10", load), "");
  EXPECT_EQ(load.friction_uNm, 100'000u);
  EXPECT_EQ(load.force_uNm, -20'000);
  EXPECT_EQ(load.inertia_g_mm2, 1'000u);
  EXPECT_NE(parse_axis_load("torque=1", load).find("only load=, friction= and force="), std::string::npos);
}

TEST(AxisCtl, StatusShowsTheTruePositionNextToAbsPosAndAxisChangesTheLoad) {
  ParseResult p = parse_board_config(
      "bus=0 cs=0 chips=2xL6470 axis.1=stops=0..,start=1280,switch=home@100:hyst=8; time=virtual", "test");
  ASSERT_TRUE(p.config) << p.error.message;
  DiagnosticLog log("off");
  DeviceBoard board(*p.config, log);
  board.with_chain(0, [](Chain& c) {
    ChainHost h(c);
    h.move(1, true, 12800);
  });
  ASSERT_TRUE(board.advance(ticks_from_ms(2000)));
  std::string out;
  ASSERT_EQ(run_control(board, "status --chip 1", out), 0) << out;
  EXPECT_NE(out.find("ABS_POS 12800 true 14080"), std::string::npos) << out;
  ASSERT_EQ(run_control(board, "status --chip 0", out), 0) << out;
  EXPECT_EQ(out.find("true"), std::string::npos) << "no axis, no true position: " << out;
  ASSERT_EQ(run_control(board, "axis", out), 0) << out;
  EXPECT_NE(out.find("chip 0: no axis"), std::string::npos) << out;
  EXPECT_NE(out.find("chip 1: ABS_POS 12800  true 14080 (1/128 step)  lost 0  synchronised"), std::string::npos) << out;
  EXPECT_NE(out.find("home open"), std::string::npos) << out;
  ASSERT_EQ(run_control(board, "axis load friction=0.3 --chip 1", out), 0) << out;
  board.with_chain(0, [](Chain& c) {
    ChainHost h(c);
    h.move(1, false, 12800);
  });
  ASSERT_TRUE(board.advance(ticks_from_ms(3000)));
  ASSERT_EQ(run_control(board, "axis --chip 1", out), 0) << out;
  EXPECT_EQ(out.find("lost 0 "), std::string::npos) << "0.3 N·m of friction is more than the drive gives: " << out;
  EXPECT_EQ(run_control(board, "axis load torque=1 --chip 1", out), 2);
  EXPECT_EQ(run_control(board, "axis load friction=0 --chip 0", out), 1);
  EXPECT_NE(out.find("chip 0 has no axis"), std::string::npos) << out;
}

TEST(AxisCtl, AnAxisChipNumberCountsAsTheBoardsNumberingSays) {
  ParseResult p = parse_board_config("bus=0 cs=0 chips=3xL6470 axis.0=start=640; numbering=mosi", "test");
  ASSERT_TRUE(p.config) << p.error.message;
  DiagnosticLog log("off");
  DeviceBoard board(*p.config, log);
  board.with_chain(0, [](Chain& c) {
    EXPECT_EQ(c.chip(0).axis(), nullptr) << "chip 0 from the MOSI end is the chain's last chip";
    ASSERT_NE(c.chip(2).axis(), nullptr);
    EXPECT_EQ(c.chip(2).axis()->true_position(), 640);
  });
  std::string out;
  ASSERT_EQ(run_control(board, "axis --chip 0", out), 0) << out;
  EXPECT_NE(out.find("chip 0: ABS_POS 0  true 640"), std::string::npos) << out;
}

}  // namespace
}  // namespace l6470emu
