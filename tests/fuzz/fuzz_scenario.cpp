// libFuzzer harness of scenario files (linux/scenario_file.hpp parse_scenario_yaml): any text
// gives a scenario or one error line naming the file, never a crash; an accepted scenario goes
// through run's exchange form (board/scenario.hpp) and reads back the same, and is written back
// as a scenario file (linux/scenario_yaml.hpp, what a campaign's reruns are made of) that reads
// back to the same steps.
#include <string_view>

#include "board/scenario.hpp"
#include "fuzz_support.hpp"
#include "linux/scenario_file.hpp"
#include "linux/scenario_yaml.hpp"

using namespace l6470emu;

namespace {

// Whether `s` is UTF-8 throughout (YAML cannot carry other bytes: a name made of them is
// written back as it is, and only the writing is checked).
bool utf8(std::string_view s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    const std::size_t len = c < 0x80 ? 1 : (c >> 5) == 6 ? 2 : (c >> 4) == 14 ? 3 : (c >> 3) == 30 ? 4 : 0;
    if (len == 0 || i + len > s.size()) return false;
    for (std::size_t k = 1; k < len; ++k)
      if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return false;
    i += len;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::count_input(size);
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const ScenarioParse r = parse_scenario_yaml(text, "fuzz.yaml");
  if (!r.scenario) {
    FUZZ_CHECK(r.error.rfind("l6470emu: scenario fuzz.yaml", 0) == 0, "error does not name the file: %.200s",
               r.error.c_str());
    FUZZ_CHECK(r.error.find('\n') == std::string::npos, "error is not one line: %.200s", r.error.c_str());
    return 0;
  }
  std::string error;
  const auto back = deserialize_scenario(serialize_scenario(*r.scenario), error);
  FUZZ_CHECK(back.has_value(), "an accepted scenario does not read back: %.200s", error.c_str());
  FUZZ_CHECK(*back == *r.scenario, "a scenario reads back differently from its exchange form");
  const std::string written = scenario_yaml(*r.scenario, "written back");
  if (!utf8(text)) return 0;
  const ScenarioParse again = parse_scenario_yaml(written, "fuzz.yaml");
  FUZZ_CHECK(again.scenario.has_value(), "a written scenario does not read: %.200s", again.error.c_str());
  Scenario a = *r.scenario, b = *again.scenario;
  for (auto& s : a.steps) s.where.clear();
  for (auto& s : b.steps) s.where.clear();
  FUZZ_CHECK(a == b, "a scenario written back reads differently");
  return 0;
}
