// Where a run's recordings are (tools/run_recordings.hpp): the per-chain files of a board of
// several chains, named from the path it recorded to, and found again from that path, with
// files that only look like one of them left out.
#include <gtest/gtest.h>

#include "board/board_config.hpp"
#include "support/trace_test_support.hpp"
#include "tools/run_recordings.hpp"

namespace l6470emu {
namespace {

using test::TempDir;

/// A native trace holding `board` as its board lines and one frame.
std::string recording(const TempDir& dir, const std::string& name, const std::string& board) {
  return dir.write(name, "l6470emu-trace 2\nchain L6470\nboard " + board + "\n0.00100000 frame 1.75us D0 | 00\n");
}

TEST(RunRecordings, ABoardOfOneChainRecordsToThePathItselfAndOfSeveralBesideIt) {
  const ParseResult one = parse_board_config("bus=0 cs=0 chips=L6470", "--chain");
  ASSERT_TRUE(one.config);
  const std::vector<ChainRecording> single = run_recordings(*one.config, "out/run.trace");
  ASSERT_EQ(single.size(), 1u);
  EXPECT_EQ(single[0].chain, "spidev0.0");
  EXPECT_EQ(single[0].path, "out/run.trace");
  const ParseResult two = parse_board_config("bus=0 cs=1 chips=L6470; bus=1 cs=0 chips=2xL6470", "--chain");
  ASSERT_TRUE(two.config);
  const std::vector<ChainRecording> both = run_recordings(*two.config, "out/run.trace.gz");
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0].chain, "spidev0.1");
  EXPECT_EQ(both[0].path, "out/run.spidev0.1.trace.gz");
  EXPECT_EQ(both[1].path, "out/run.spidev1.0.trace.gz");
}

TEST(RunRecordings, ThePathASeveralChainRunRecordedToFindsItsChainsInBusAndChipSelectOrder) {
  TempDir dir;
  const std::string b = recording(dir, "run.spidev1.0.trace", "bus=1 cs=0 chips=L6470");
  const std::string a = recording(dir, "run.spidev0.1.trace", "bus=0 cs=1 chips=L6470");
  recording(dir, "run.old.trace", "bus=0 cs=0 chips=L6470");  // named for no chain it records
  dir.write("run.notes.trace", "not a trace\n");
  recording(dir, "other.spidev0.0.trace", "bus=0 cs=0 chips=L6470");  // another run's
  const std::vector<ChainRecording> found = find_run_recordings(dir.file("run.trace"));
  ASSERT_EQ(found.size(), 2u);
  EXPECT_EQ(found[0].chain, "spidev0.1");
  EXPECT_EQ(found[0].path, a);
  EXPECT_EQ(found[1].chain, "spidev1.0");
  EXPECT_EQ(found[1].path, b);
}

TEST(RunRecordings, APathThatIsAFileOfItsOwnOrHasNoChainsBesideItFindsNothing) {
  TempDir dir;
  recording(dir, "run.spidev0.1.trace", "bus=0 cs=1 chips=L6470");
  const std::string own = recording(dir, "run.trace", "bus=0 cs=0 chips=L6470");
  EXPECT_TRUE(find_run_recordings(own).empty()) << "a trace of its own is itself";
  EXPECT_TRUE(find_run_recordings(dir.file("nothing.trace")).empty());
  EXPECT_TRUE(find_run_recordings(dir.file("no/such/folder/run.trace")).empty());
}

}  // namespace
}  // namespace l6470emu
