// run's progress line: the page a program under the preload keeps its board time and SPI
// messages in, and the line drawn from it.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include "board/run_report.hpp"
#include "run_program.hpp"
#include "tools/run_progress.hpp"

namespace l6470emu::test {
namespace {

TEST(RunProgress, AProgramUnderThePreloadKeepsItsBoardTimeAndItsMessagesInThePage) {
  const std::string why = missing_prerequisites();
  if (!why.empty()) GTEST_SKIP() << why;
  const std::string page = temp_socket_path("progress") + ".page";
  std::ofstream(page, std::ios::binary) << std::string(kRunProgressBytes, '\0');
  const RunResult r = run_program({client("spidev_reader"), "/dev/spidev0.0", "10", "0x03", "0"},
                                  {{"LD_PRELOAD", preload_library()}, {"L6470EMU_CHAIN", "bus=0 cs=0 chips=L6470 time=virtual"},
                                   {kRunProgressEnv, page}});
  EXPECT_EQ(r.status, 0) << r.err;
  std::ifstream in(page, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  ASSERT_EQ(bytes.size(), kRunProgressBytes);
  RunProgress p;
  std::memcpy(&p.tick, bytes.data(), 8);
  std::memcpy(&p.messages, bytes.data() + 8, 8);
  EXPECT_EQ(p.messages, 10u);  // one SPI_IOC_MESSAGE per read
  EXPECT_GT(p.tick, 0u);       // each message took its bus time
  unlink(page.c_str());
}

TEST(RunProgress, TheLineSaysTheBoardTimeTheMessagesAndTheWallTime) {
  EXPECT_EQ(format_run_progress(RunProgress{50'000'000, 3456}, 4.4),
            "l6470emu run: 12.500000 s of board time, 3456 SPI messages (4 s of wall time)");
  EXPECT_EQ(format_run_progress(RunProgress{0, 1}, 2), "l6470emu run: 0.000000 s of board time, 1 SPI message (2 s of wall time)");
}

}  // namespace
}  // namespace l6470emu::test
