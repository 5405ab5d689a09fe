// The snapshot plan a campaign hands the preload: written and read back, and anything else
// refused with the line that is wrong.
#include <gtest/gtest.h>

#include "linux/fork_plan.hpp"

namespace l6470emu::test {
namespace {

TEST(ForkPlan, APlanReadsBackAsItWasWritten) {
  ForkPlan p;
  p.children = 2;
  p.wall_ns = 60'000'000'000;
  p.recordings = {"/tmp/c/snapshots/run.trace", "/tmp/c/snapshots/run.spidev0.1.trace"};
  p.jobs = {{609, "/tmp/c/0"}, {609, "/tmp/c/7"}, {1113, "/tmp/c dir/1"}};
  std::string error;
  const auto back = parse_fork_plan(format_fork_plan(p), error);
  ASSERT_TRUE(back) << error;
  EXPECT_EQ(back->children, 2u);
  EXPECT_EQ(back->wall_ns, p.wall_ns);
  EXPECT_EQ(back->recordings, p.recordings);
  ASSERT_EQ(back->jobs.size(), 3u);
  EXPECT_EQ(back->jobs[2].tick, 1113u);
  EXPECT_EQ(back->jobs[2].dir, "/tmp/c dir/1");
}

TEST(ForkPlan, AnythingElseIsRefusedNamingItsLine) {
  const std::string head = "l6470emu fork plan 1\n";
  for (const auto& [text, said] : std::vector<std::pair<std::string, std::string>>{
           {"", "empty"},
           {"a plan\n", "line 1: not a fork plan"},
           {head + "children 0\n", "line 2: children takes a number above 0"},
           {head + "wall_ns -5\n", "line 2: wall_ns"},
           {head + "record relative.trace\n", "line 2: record takes an absolute path"},
           {head + "job 10\n", "line 2: job takes a tick and a directory"},
           {head + "job 10 /a\njob 9 /b\n", "line 3: the jobs are not in order of tick"},
           {head + "job 10 relative\n", "line 2: a job's directory is an absolute path"},
           {head + "jobs 3\n", "line 2: unknown key jobs"},
           {head + "job 10 /a", "the plan does not end with a newline"},
       }) {
    std::string error;
    EXPECT_FALSE(parse_fork_plan(text, error)) << text;
    EXPECT_NE(error.find(said), std::string::npos) << text << " -> " << error;
  }
}

}  // namespace
}  // namespace l6470emu::test
