// Scenarios written back as files: what scenario_yaml writes reads back to the same steps,
// durations to the tick, names with any characters, every trigger, action and expectation.
#include <gtest/gtest.h>

#include <string>

#include "linux/scenario_file.hpp"
#include "linux/scenario_yaml.hpp"

namespace l6470emu::test {
namespace {

Scenario read(const std::string& text) {
  const ScenarioParse p = parse_scenario_yaml(text, "s.yaml");
  EXPECT_TRUE(p.scenario) << p.error << "\n" << text;
  return p.scenario.value_or(Scenario{});
}

// Steps equal but for where they stand in their files.
void expect_same_steps(Scenario a, Scenario b) {
  for (auto& s : a.steps) s.where.clear();
  for (auto& s : b.steps) s.where.clear();
  EXPECT_EQ(a, b);
}

TEST(ScenarioYaml, EveryTriggerActionAndExpectationReadsBackAsItWas) {
  const Scenario original = read(R"(name: all of it
timeout: 30s
steps:
  - at: 250ms
    do: {sw: close, chip: 1}
  - at: 1.00000025s
    do: {sw: open}
  - on: {position: -1000, chip: 0}
    after: 10ms
    do: {fault: ocd}
  - on: {true_position: 128000}
    do: {fault: uvlo, clear: true}
  - on: {busy: fall, count: 3}
    delay: 1us
    do: {stby_rst: low}
  - on: {busy: rise}
    do: {stby_rst: high}
  - at: 1s
    do: {dir: low}
  - on: {command: GoUntil, count: 2}
    chain: spidev0.0
    do: {load: {inertia_g_mm2: 5, friction_uNm: 7, force_uNm: -20000}}
  - at: 2s
    do: {thermal: bridge_shutdown}
  - at: 2s
    do: {adcin: 17}
  - at: 3s
    do: {block: -4096}
  - at: 3s
    do: {supply_mV: 7000}
  - at: 3s
    do: {fault: stall_b}
  - at: 3s
    do: {fault: reset}
  - at: 3s
    do: {fault: miso_flip, bit: 2}
  - at: 3s
    do: {fault: lost_frame}
  - at: 4s
    do: {serial: "G 100\r\n\ttab \"quoted\" back\\slash: colon # hash"}
  - on: {command: Move}
    do: {serial: x}
  - at: end
    chip: 1
    expect: {register: ABS_POS, value: -5, tolerance: 3}
  - at: end
    expect: {true_position: 640, tolerance: 2}
  - at: end
    expect: {status: {OCD: 0, UVLO: 1}}
  - at: end
    expect: {busy_pulse: {min: 1ms, max: 2.5s, pulse: 1}}
  - at: end
    expect: {busy_pulse: {min: 0s}}
  - at: end
    expect: {command: SoftStop, sent: false}
  - at: end
    expect: {command: Move, sent: true}
  - at: end
    expect: {command: GetStatus, count: 12}
  - at: end
    expect: {frames: {min: 4}}
  - at: end
    expect: {frames: 9}
  - at: end
    expect: {sanitizer: clean}
)");
  ASSERT_EQ(original.steps.size(), 29u);
  EXPECT_EQ(original.steps[16].action->text, "G 100\r\n\ttab \"quoted\" back\\slash: colon # hash");
  const std::string written = scenario_yaml(original, "made by a test\nsecond line");
  EXPECT_EQ(written.rfind("# made by a test\n# second line\n", 0), 0u) << written;
  expect_same_steps(original, read(written));
}

TEST(ScenarioYaml, DurationsAreWrittenToTheTick) {
  for (const Tick t : {Tick{0}, Tick{1}, Tick{3}, Tick{4'000'000}, Tick{4'000'001}, Tick{14'400'000'000'123}}) {
    const auto back = parse_scenario_duration(scenario_duration_text(t));
    ASSERT_TRUE(back) << scenario_duration_text(t);
    EXPECT_EQ(*back, t) << scenario_duration_text(t);
  }
  EXPECT_EQ(scenario_duration_text(1), "0.00000025s");
  EXPECT_EQ(scenario_duration_text(6'000'000), "1.5s");
}

TEST(ScenarioYaml, ANameWithQuotesNewlinesAndColonsReadsBack) {
  Scenario s;
  s.name = "a \"name\": with\\ a\nnewline # and a comment sign, \xC2\x85 NEL, \xE2\x80\xA8 LS, \xEF\xBB\xBF BOM, \x7f";
  const Scenario back = read(scenario_yaml(s));
  EXPECT_EQ(back.name, s.name);
  EXPECT_TRUE(back.steps.empty());
}

}  // namespace
}  // namespace l6470emu::test
