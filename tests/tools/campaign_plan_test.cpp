// The campaign's plan and report without running anything: injection points from what a chip
// decoded, faults by variant, verdicts from run's outcome, --fail-on, the JSON both ways and
// shards merged.
#include <gtest/gtest.h>

#include "core/variant.hpp"
#include "tools/campaign_plan.hpp"
#include "tools/campaign_report.hpp"

namespace l6470emu::test {
namespace {

DecodedCommand at(Command c, Tick start, std::uint8_t param = 0) { return DecodedCommand{c, param, start, start + 100}; }

// A driver's run: three SetParams, a GetStatus, Move, polls while busy, polls while idle, SoftStop.
ChipRun a_driver_run() {
  ChipRun c;
  c.chain_name = "spidev0.0";
  c.variant = &l6470();
  c.commands = {at(Command::SetParam, 1000, 5), at(Command::SetParam, 2000, 6), at(Command::SetParam, 3000, 7),
                at(Command::GetStatus, 4000), at(Command::Move, 5000)};
  for (Tick t = 10'000; t <= 90'000; t += 10'000) c.commands.push_back(at(Command::GetStatus, t));
  c.commands.push_back(at(Command::SoftStop, 100'000));
  c.busy_low = {{5100, 55'000}};
  return c;
}

TEST(CampaignPlan, PhasesAreAfterConfigurationAtTheMotionDuringItWhileIdleAndBeforeTheLastCommand) {
  const auto points = injection_points(a_driver_run(), PointSelection::phases);
  ASSERT_EQ(points.size(), 5u);
  EXPECT_EQ(points[0].name, "after_config");
  EXPECT_EQ(points[0].tick, 3101u);
  EXPECT_EQ(points[0].after_command, "SetParam");
  EXPECT_EQ(points[1].name, "at_Move");
  EXPECT_EQ(points[1].tick, 5101u);
  EXPECT_EQ(points[2].name, "during_motion");
  EXPECT_EQ(points[2].tick, 5100u + (55'000 - 5100) / 2);
  EXPECT_EQ(points[3].name, "idle_polling");
  EXPECT_GT(points[3].tick, 55'000u);
  EXPECT_EQ(points[4].name, "before_last_command");
  EXPECT_EQ(points[4].tick, 99'999u);
  for (const auto& p : points) EXPECT_LT(p.tick, 100'000u) << p.name;
}

TEST(CampaignPlan, EveryCommandGivesAPointAfterEachCommandButTheLast) {
  const ChipRun run = a_driver_run();
  const auto points = injection_points(run, PointSelection::every_command);
  ASSERT_EQ(points.size(), run.commands.size() - 1);
  EXPECT_EQ(points[0].name, "after_SetParam");
  EXPECT_EQ(points[1].name, "after_SetParam_2");
  EXPECT_EQ(points[4].name, "after_Move");
  EXPECT_EQ(points.back().name, "after_GetStatus_10");
  for (std::size_t i = 0; i < points.size(); ++i) EXPECT_EQ(points[i].tick, run.commands[i].end + 1);
}

TEST(CampaignPlan, AChipNeverSpokenToHasNoPoints) {
  ChipRun c;
  EXPECT_TRUE(injection_points(c, PointSelection::phases).empty());
  EXPECT_TRUE(injection_points(c, PointSelection::every_command).empty());
}

TEST(CampaignPlan, FaultsFollowTheVariantAndTheBoard) {
  EXPECT_NE(fault_unavailable(CampaignFault::uvlo_adc, l6470(), false), "");
  EXPECT_EQ(fault_unavailable(CampaignFault::uvlo_adc, l6480(), false), "");
  EXPECT_NE(fault_unavailable(CampaignFault::stall_a, l6472(), false), "");
  EXPECT_EQ(fault_unavailable(CampaignFault::stall_a, l6470(), false), "");
  EXPECT_NE(fault_unavailable(CampaignFault::block, l6470(), false), "");
  EXPECT_EQ(fault_unavailable(CampaignFault::block, l6470(), true), "");
  EXPECT_EQ(fault_flag(CampaignFault::stall_a, l6480()), "STALL_A");
  EXPECT_EQ(fault_flag(CampaignFault::stall_a, l6470()), "STEP_LOSS_A");
  EXPECT_EQ(fault_flag(CampaignFault::ocd, l6470()), "OCD");
  EXPECT_EQ(find_campaign_fault("thermal_warning")->fault, CampaignFault::thermal_warning);
  EXPECT_EQ(find_campaign_fault("thermal"), nullptr);
}

TEST(CampaignPlan, AnL6474IsOfferedOnlyTheFaultsItHas) {
  // No stall detection, no ADC undervoltage, no SW input; overcurrent, thermal and UVLO it has.
  for (CampaignFault f : {CampaignFault::stall_a, CampaignFault::stall_b, CampaignFault::uvlo_adc, CampaignFault::sw_close})
    EXPECT_NE(fault_unavailable(f, l6474(), false), "") << static_cast<int>(f);
  EXPECT_EQ(fault_unavailable(CampaignFault::sw_close, l6474(), false), "L6474 has no SW input");
  for (CampaignFault f : {CampaignFault::ocd, CampaignFault::thermal_warning, CampaignFault::thermal_bridge_shutdown,
                          CampaignFault::thermal_device_shutdown, CampaignFault::uvlo, CampaignFault::reset,
                          CampaignFault::stby_pulse, CampaignFault::miso_flip, CampaignFault::lost_frame})
    EXPECT_EQ(fault_unavailable(f, l6474(), false), "") << static_cast<int>(f);
  EXPECT_EQ(fault_unavailable(CampaignFault::sw_close, l6470(), false), "");
}

TEST(CampaignPlan, AnL6474sPhasesAreAfterItsConfigurationAndAtItsEnable) {
  // Enable is where an L6474 starts to be driven (its steps come from STCK, not from SPI).
  ChipRun c;
  c.chain_name = "spidev0.0";
  c.variant = &l6474();
  c.commands = {at(Command::SetParam, 1000, 0x16), at(Command::SetParam, 2000, 0x09), at(Command::Enable, 3000)};
  for (Tick t = 10'000; t <= 50'000; t += 10'000) c.commands.push_back(at(Command::GetStatus, t));
  c.commands.push_back(at(Command::Disable, 60'000));
  const auto points = injection_points(c, PointSelection::phases);
  ASSERT_GE(points.size(), 3u);
  EXPECT_EQ(points[0].name, "after_config");
  EXPECT_EQ(points[1].name, "at_Enable");
  EXPECT_EQ(points.back().name, "before_last_command");
}

TEST(CampaignPlan, AConditionFaultIsRaisedAtItsTickAndClearedTenMillisecondsLater) {
  ChipRun c = a_driver_run();
  c.number = 2;
  const auto steps = fault_steps(CampaignFault::ocd, c, 5000, 0);
  ASSERT_EQ(steps.size(), 2u);
  EXPECT_EQ(steps[0].when.tick, 5000u);
  EXPECT_EQ(steps[0].action->value, 1);
  EXPECT_EQ(steps[0].action->chip, (ScenarioChip{"spidev0.0", 2}));
  EXPECT_EQ(steps[1].when.tick, 5000u + kFaultHoldTicks);
  EXPECT_EQ(steps[1].action->value, 0);
}

TEST(CampaignVerdict, EachWayARunEndsHasItsVerdict) {
  auto with = [](int status, bool exited = true) {
    RunOutcome o;
    o.status = status;
    o.exited = exited;
    return std::optional<RunOutcome>(o);
  };
  EXPECT_EQ(classify_rerun(with(0), false), Verdict::survived);
  EXPECT_EQ(classify_rerun(with(1), false), Verdict::silent_failure);
  EXPECT_EQ(classify_rerun(with(3), false), Verdict::hang);
  EXPECT_EQ(classify_rerun(with(4), false), Verdict::deadlock);
  EXPECT_EQ(classify_rerun(with(5), false), Verdict::detected);
  EXPECT_EQ(classify_rerun(with(6), false), Verdict::detected);
  EXPECT_EQ(classify_rerun(with(6, false), false), Verdict::crash);
  EXPECT_EQ(classify_rerun(with(7), false), Verdict::crash);
  EXPECT_EQ(classify_rerun(std::nullopt, false), Verdict::crash);
  EXPECT_EQ(classify_rerun(with(0), true), Verdict::hang);
}

TEST(CampaignVerdict, FailOnTakesVerdictsAndSurvivedUnreadAndNamesANearMiss) {
  std::string error;
  const auto on = parse_fail_on("hang,survived-unread", error);
  ASSERT_TRUE(on) << error;
  RerunResult r;
  r.verdict = Verdict::survived;
  r.flag_read = false;
  EXPECT_TRUE(r.fails(*on));
  r.flag_read = true;
  EXPECT_FALSE(r.fails(*on));
  r.verdict = Verdict::silent_failure;
  EXPECT_FALSE(r.fails(*on));
  EXPECT_TRUE(r.fails(FailOn{}));
  EXPECT_FALSE(parse_fail_on("hnag", error));
  EXPECT_NE(error.find("did you mean hang?"), std::string::npos) << error;
}

CampaignReport a_report() {
  CampaignReport r;
  r.program = {"./driver", "--fast"};
  r.board = "chips=L6470";
  r.oracle = "clean_run";
  r.faults = {"ocd", "uvlo"};
  r.points = "phases";
  r.clean_end_tick = 4'000'000;
  r.rerun_timeout_ticks = 44'000'000;
  r.total = 4;
  for (std::size_t i = 0; i < 4; ++i) {
    RerunResult x;
    x.index = i;
    x.fault = i < 2 ? "ocd" : "uvlo";
    x.chain = "spidev0.0";
    x.point = i % 2 ? "during_motion" : "at_Move";
    x.tick = 1000 * (i % 2 + 1);
    x.after_command = "Move";
    x.verdict = i == 1 ? Verdict::silent_failure : Verdict::detected;
    x.flag_read = i != 3;
    x.exit = i == 1 ? 1 : 6;
    x.program = "exited with status 1";
    if (i == 1) x.first_failure = ScenarioFailure{"the clean run's end", "ABS_POS", 9, "spidev0.0 chip 0", "5", "3"};
    x.command = "l6470emu run --chain chips=L6470 --scenario c.yaml -- ./driver --fast";
    r.reruns.push_back(x);
  }
  return r;
}

TEST(CampaignReport, TheJsonReadsBackToTheSameReport) {
  const CampaignReport r = a_report();
  std::string error;
  const auto back = parse_campaign_json(campaign_json(r), error);
  ASSERT_TRUE(back) << error;
  EXPECT_EQ(campaign_json(*back), campaign_json(r));
  EXPECT_EQ(campaign_summary(r), "4 reruns: 3 detected, 1 silent_failure");
}

TEST(CampaignReport, ShardsMergeIntoTheWholeAndOverlapsOrStrangersAreRefused) {
  const CampaignReport whole = a_report();
  std::vector<CampaignReport> shards;
  for (unsigned k = 1; k <= 3; ++k) {
    CampaignReport s = whole;
    s.shard = std::make_pair(k, 3u);
    s.reruns.clear();
    for (const RerunResult& x : whole.reruns)
      if (x.index % 3 == k - 1) s.reruns.push_back(x);
    shards.push_back(s);
  }
  std::string error;
  std::vector<CampaignReport> shuffled{shards[2], shards[0], shards[1]};
  const auto merged = merge_campaign_reports(shuffled, error);
  ASSERT_TRUE(merged) << error;
  EXPECT_EQ(campaign_json(*merged), campaign_json(whole));
  EXPECT_FALSE(merge_campaign_reports({shards[0], shards[0]}, error));
  EXPECT_NE(error.find("in two of the reports"), std::string::npos) << error;
  CampaignReport other = shards[1];
  other.board = "chips=L6480";
  EXPECT_FALSE(merge_campaign_reports({shards[0], other}, error));
  const auto partial = merge_campaign_reports({shards[0], shards[1]}, error);
  ASSERT_TRUE(partial);
  EXPECT_FALSE(partial->complete);
}

TEST(CampaignReport, TheJUnitReportHasOneCaseForEachFaultAndChipNamedTheSameWhateverTheVerdict) {
  CampaignReport r = a_report();
  const std::string failing = campaign_junit(r, FailOn{});
  for (auto& x : r.reruns) x.verdict = Verdict::survived;
  const std::string passing = campaign_junit(r, FailOn{});
  for (const std::string name : {"ocd spidev0.0 chip 0", "uvlo spidev0.0 chip 0"}) {
    EXPECT_NE(failing.find("name=\"" + name + "\""), std::string::npos) << failing;
    EXPECT_NE(passing.find("name=\"" + name + "\""), std::string::npos) << passing;
  }
  EXPECT_NE(failing.find("failures=\"1\""), std::string::npos) << failing;
  EXPECT_NE(failing.find("reproduce: l6470emu run"), std::string::npos) << failing;
  EXPECT_NE(passing.find("failures=\"0\""), std::string::npos) << passing;
}

}  // namespace
}  // namespace l6470emu::test
