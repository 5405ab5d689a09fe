// libFuzzer harness of the board description parser (board/board_config.hpp parse_board_config):
// any text gives a config or one error line, never a crash; an accepted config's own
// description (describe_board_config, what `serve` prints) reads back to the same chains,
// their microcontroller pins and a firmware run's timing.
#include <string_view>

#include "board/board_config.hpp"
#include "fuzz_support.hpp"

using namespace l6470emu;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::count_input(size);
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const ParseResult r = parse_board_config(text, "fuzz.conf");
  if (!r.config) {
    FUZZ_CHECK(!r.error.message.empty(), "no config and no error");
    FUZZ_CHECK(r.error.message.find('\n') == std::string::npos, "error is not one line: %.200s",
               r.error.message.c_str());
    return 0;
  }
  const BoardConfig& a = *r.config;
  if (a.chains.empty()) return 0;  // socket= only: nothing to describe
  const std::string description = describe_board_config(a);
  const ParseResult back = parse_board_config(description, "description");
  FUZZ_CHECK(back.config.has_value(), "the description of an accepted config does not parse: %.300s\n%.300s",
             back.error.message.c_str(), description.c_str());
  const BoardConfig& b = *back.config;
  FUZZ_CHECK(a.chains.size() == b.chains.size(), "description has %zu chains, the config %zu", b.chains.size(),
             a.chains.size());
  for (std::size_t i = 0; i < a.chains.size(); ++i) {
    const ChainConfig &x = a.chains[i], &y = b.chains[i];
    FUZZ_CHECK(x.bus == y.bus && x.cs == y.cs && x.path == y.path && x.chips == y.chips && x.gpiochip == y.gpiochip &&
                   x.max_speed_hz == y.max_speed_hz && x.mode == y.mode && x.bufsiz == y.bufsiz &&
                   x.axes == y.axes && x.pins == y.pins,
               "chain %zu reads back differently from its description:\n%.300s", i, description.c_str());
  }
  FUZZ_CHECK(a.time.virtual_time == b.time.virtual_time && a.trace == b.trace && a.firmware == b.firmware,
             "time or trace reads back differently from the description:\n%.300s", description.c_str());
  return 0;
}
