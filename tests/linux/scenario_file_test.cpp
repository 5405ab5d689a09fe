// Scenario files: the YAML schema of docs/scenarios.md read into the model, and every mistake
// one line naming the file, the line and the key, with the near miss when there is one.
#include <gtest/gtest.h>

#include <string>

#include "linux/scenario_file.hpp"

namespace l6470emu::test {
namespace {

std::string error_of(const std::string& text) {
  const ScenarioParse p = parse_scenario_yaml(text, "s.yaml");
  EXPECT_FALSE(p.scenario);
  return p.error;
}

TEST(ScenarioFile, ASecondDocumentOrATimeoutOfZeroIsAnErrorNotLeftOut) {
  EXPECT_EQ(error_of("steps: []\n---\nsteps:\n  - at: end\n    expect: {frames: 99}\n"),
            "l6470emu: scenario s.yaml:2: a second YAML document (after '---' or '...'): a scenario file holds one");
  EXPECT_EQ(error_of("steps: []\n...\nname: later\n"),
            "l6470emu: scenario s.yaml:3: a second YAML document (after '---' or '...'): a scenario file holds one");
  EXPECT_EQ(error_of("---\n---\nsteps: []\n"),
            "l6470emu: scenario s.yaml:2: a second YAML document (after '---' or '...'): a scenario file holds one");
  EXPECT_EQ(error_of("timeout: 0\nsteps: []\n"),
            "l6470emu: scenario s.yaml:1: key 'timeout': 0 is no time limit a run can have (leave timeout: out for none)");
  EXPECT_TRUE(parse_scenario_yaml("# a comment\n--- # the one document\nsteps: []\n...\n", "s.yaml").scenario);
}

TEST(ScenarioFile, AMissingFileIsOneLineSayingWhy) {
  EXPECT_EQ(load_scenario_file("/no/such/scenario.yaml").error,
            "l6470emu: scenario /no/such/scenario.yaml: cannot be read (No such file or directory)");
}

TEST(ScenarioFile, AHomingScenarioReadsIntoStepsWithTheirLines) {
  const ScenarioParse p = parse_scenario_yaml(R"(name: homing
timeout: 30s
steps:
  - at: 250ms
    do: {sw: close, chip: 1}
  - on: {position: -1000, chip: 0}
    after: 10ms
    do: {fault: ocd}
  - on: {command: GoUntil, count: 2}
    chain: spidev0.0
    do: {load: {force_uNm: -20000}}
  - at: end
    chip: 1
    expect: {register: ABS_POS, value: 0, tolerance: 3}
  - at: end
    expect: {status: {OCD: 0, UVLO: 1}}
  - at: end
    expect: {busy_pulse: {min: 1ms, max: 2.5s, pulse: 1}}
  - at: end
    expect: {command: SoftStop, sent: false}
  - at: end
    expect: {frames: {min: 4}}
)",
                                              "home.yaml");
  ASSERT_TRUE(p.scenario) << p.error;
  const Scenario& s = *p.scenario;
  EXPECT_EQ(s.name, "homing");
  EXPECT_EQ(s.timeout_ticks, Tick{30} * kTicksPerSecond);
  ASSERT_EQ(s.steps.size(), 8u);
  EXPECT_EQ(s.steps[0].where, "home.yaml:4");
  EXPECT_EQ(s.steps[0].when.tick, ticks_from_ms(250));
  EXPECT_EQ(s.steps[0].action->kind, ScenarioAction::Kind::sw);
  EXPECT_FALSE(s.steps[0].action->level);
  EXPECT_EQ(s.steps[0].action->chip.number, 1u);
  EXPECT_EQ(s.steps[1].when.kind, ScenarioTrigger::Kind::position);
  EXPECT_EQ(s.steps[1].when.position, -1000);
  EXPECT_EQ(s.steps[1].when.tick, ticks_from_ms(10));
  EXPECT_EQ(s.steps[1].action->fault, TraceFault::OCD);
  EXPECT_EQ(s.steps[2].when.count, 2u);
  EXPECT_EQ(s.steps[2].action->chip.chain, "spidev0.0");
  EXPECT_EQ(s.steps[2].action->load.force_uNm, -20000);
  EXPECT_EQ(s.steps[3].expect->chip.number, 1u);
  EXPECT_EQ(s.steps[3].expect->tolerance, 3);
  EXPECT_EQ(s.steps[4].expect->flags.size(), 2u);
  EXPECT_EQ(s.steps[5].expect->max_ticks, Tick{10'000'000});
  EXPECT_EQ(s.steps[6].expect->count, 0u);
  EXPECT_EQ(s.steps[7].expect->min_count, 4u);
  EXPECT_EQ(s.steps[7].where, "home.yaml:21");
}

TEST(ScenarioFile, AMisspelledKeyIsNamedWithItsLineAndTheNearMiss) {
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {sw: close}\n  - at: end\n    expcet: {frames: 3}\n"),
            "l6470emu: scenario s.yaml:5: key 'expcet': unknown (did you mean expect?) in a step; known: at, on, after, "
            "delay, chip, chain, do, expect");
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {sw: shut}\n"),
            "l6470emu: scenario s.yaml:3: key 'sw': 'shut' is not one of close, open");
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {falt: ocd}\n"),
            "l6470emu: scenario s.yaml:3: key 'falt': unknown (did you mean fault?) in do:; known: sw, stby_rst, dir, fault, "
            "thermal, adcin, load, block, supply_mV, serial, clear, bit, chip, chain");
  EXPECT_EQ(error_of("steps:\n  - at: 1.0000001s\n    do: {sw: close}\n"),
            "l6470emu: scenario s.yaml:2: key 'at': expects a duration (250ns, 1us, 10ms, 2.5s, 1min: whole ticks of "
            "250 ns), got '1.0000001s'");
  EXPECT_EQ(error_of("steps:\n  - at: end\n    expect: {register: ABS_POS, value: zero}\n"),
            "l6470emu: scenario s.yaml:3: key 'value': expects a whole number, got 'zero'");
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    expect: {busy_pulse: {max: 1s}}\n"),
            "l6470emu: scenario s.yaml:3: key 'busy_pulse': BUSY pulses are judged at the end: write at: end");
  EXPECT_EQ(error_of("steps:\n  - at: [1s\n"), "l6470emu: scenario s.yaml:3: not YAML: end of sequence flow not found");
  EXPECT_EQ(error_of(""), "l6470emu: scenario s.yaml: the file is empty: a scenario needs steps:");
  EXPECT_EQ(error_of(std::string(100, '[')), "l6470emu: scenario s.yaml:1: nested deeper than a scenario can be");
  EXPECT_EQ(error_of("steps:\n  - at: end\n    expect: {sanitizer: dirty}\n"),
            "l6470emu: scenario s.yaml:3: key 'sanitizer': takes clean (no rule of the chip broken)");
}

TEST(ScenarioFile, TheOneShotFaultsReadIntoTheirTraceFaults) {
  const ScenarioParse p = parse_scenario_yaml(R"(steps:
  - at: 1.25s
    do: {fault: reset, chip: 0}
  - at: 2s
    do: {fault: miso_flip, bit: 3, chip: 1}
  - at: 3s
    do: {fault: miso_flip}
  - at: 4s
    do: {fault: lost_frame, chip: 2}
)",
                                              "f.yaml");
  ASSERT_TRUE(p.scenario) << p.error;
  const Scenario& s = *p.scenario;
  ASSERT_EQ(s.steps.size(), 4u);
  EXPECT_EQ(s.steps[0].action->kind, ScenarioAction::Kind::fault);
  EXPECT_EQ(s.steps[0].action->fault, TraceFault::POWER_CYCLE);
  EXPECT_EQ(s.steps[0].when.tick, ticks_from_ms(1250));
  EXPECT_EQ(s.steps[1].action->fault, TraceFault::MISO_FLIP);
  EXPECT_EQ(s.steps[1].action->value, 3u);
  EXPECT_EQ(s.steps[1].action->chip.number, 1u);
  EXPECT_EQ(s.steps[2].action->fault, TraceFault::MISO_FLIP);
  EXPECT_EQ(s.steps[2].action->value, 7u) << "bit 7, the MSB, by default";
  EXPECT_EQ(s.steps[3].action->fault, TraceFault::LOST_FRAME);
  EXPECT_EQ(s.steps[3].action->chip.number, 2u);
}

TEST(ScenarioFile, AMisspelledOneShotFaultIsNamedWithTheNearMiss) {
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {fault: rest}\n"),
            "l6470emu: scenario s.yaml:3: key 'fault': 'rest' is not one of ocd, uvlo, uvlo_adc, stall_a, stall_b, reset, "
            "miso_flip, lost_frame (did you mean reset?)");
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {fault: miso_flp}\n"),
            "l6470emu: scenario s.yaml:3: key 'fault': 'miso_flp' is not one of ocd, uvlo, uvlo_adc, stall_a, stall_b, "
            "reset, miso_flip, lost_frame (did you mean miso_flip?)");
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {fault: lost_frme}\n"),
            "l6470emu: scenario s.yaml:3: key 'fault': 'lost_frme' is not one of ocd, uvlo, uvlo_adc, stall_a, stall_b, "
            "reset, miso_flip, lost_frame (did you mean lost_frame?)");
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {fault: miso_flip, bti: 3}\n"),
            "l6470emu: scenario s.yaml:3: key 'bti': unknown (did you mean bit?) in do:; known: sw, stby_rst, dir, fault, "
            "thermal, adcin, load, block, supply_mV, serial, clear, bit, chip, chain");
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {fault: miso_flip, bit: 8}\n"),
            "l6470emu: scenario s.yaml:3: key 'bit': 8 is out of range (0..7)");
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {fault: reset, clear: true}\n"),
            "l6470emu: scenario s.yaml:3: key 'clear': not with fault: reset (it happens once: nothing to clear)");
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {fault: ocd, bit: 2}\n"),
            "l6470emu: scenario s.yaml:3: key 'bit': only with fault: miso_flip");
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {fault: lost_frame, bit: 2}\n"),
            "l6470emu: scenario s.yaml:3: key 'bit': only with fault: miso_flip");
}

TEST(ScenarioFile, SerialTextReadsAsItIsWrittenAndNamesNoChip) {
  const ScenarioParse p = parse_scenario_yaml(R"(steps:
  - at: 500ms
    do: {serial: "MOVE 12800\n"}
  - on: {command: Move}
    do: {serial: 'plain: text'}
)",
                                              "f.yaml");
  ASSERT_TRUE(p.scenario) << p.error;
  ASSERT_EQ(p.scenario->steps.size(), 2u);
  const ScenarioAction& a = *p.scenario->steps[0].action;
  EXPECT_EQ(a.kind, ScenarioAction::Kind::serial);
  EXPECT_EQ(a.text, "MOVE 12800\n");
  EXPECT_EQ(p.scenario->steps[0].when.tick, ticks_from_ms(500));
  EXPECT_EQ(p.scenario->steps[1].action->text, "plain: text");
}

TEST(ScenarioFile, SerialTextThatIsEmptyOrAimedAtAChipIsNamed) {
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {serial: \"\"}\n"),
            "l6470emu: scenario s.yaml:3: key 'serial': types nothing: give the text, e.g. \"G 100\\n\"");
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {serial: x, chip: 1}\n"),
            "l6470emu: scenario s.yaml:3: key 'chip': not with serial: (the text goes to the program's Serial, not to a chip)");
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {serial: [1, 2]}\n"),
            "l6470emu: scenario s.yaml:3: key 'serial': expects a single value");
  EXPECT_EQ(error_of("steps:\n  - at: 1s\n    do: {serial: x, sw: close}\n"),
            "l6470emu: scenario s.yaml:3: key 'do': names exactly one action: sw, stby_rst, dir, fault, thermal, adcin, load, "
            "block, supply_mV or serial");
  EXPECT_EQ(error_of("steps:\n  - at: end\n    do: {serial: x}\n"),
            "l6470emu: scenario s.yaml:3: key 'do': nothing can be done at the end; use expect:");
}

TEST(ScenarioFile, DurationsAreWholeTicksOfTheChip) {
  EXPECT_EQ(parse_scenario_duration("250ns"), Tick{1});
  EXPECT_EQ(parse_scenario_duration("1us"), Tick{4});
  EXPECT_EQ(parse_scenario_duration("2.5s"), Tick{10'000'000});
  EXPECT_EQ(parse_scenario_duration("3"), Tick{12'000'000});
  EXPECT_EQ(parse_scenario_duration("1min"), Tick{240'000'000});
  EXPECT_FALSE(parse_scenario_duration("100ns"));
  EXPECT_FALSE(parse_scenario_duration("-1s"));
  EXPECT_FALSE(parse_scenario_duration("1 fortnight"));
  EXPECT_FALSE(parse_scenario_duration("99999999999999999999s"));
}


}  // namespace
}  // namespace l6470emu::test
