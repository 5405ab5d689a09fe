// The waits a process of a run publishes (linux/process_waits.hpp): the text round-trips, and
// anything else is refused rather than half read.
#include "linux/process_waits.hpp"

#include <gtest/gtest.h>

namespace l6470emu {
namespace {

TEST(ProcessWaits, EveryKindOfDependencyAndTheThreadLinesComeBackAsTheyWere) {
  ProcessWaits w;
  WaitDependency child;
  child.kind = WaitDependency::Kind::child;
  child.pid = 4242;
  WaitDependency pipe;
  pipe.kind = WaitDependency::Kind::pipe;
  pipe.inode = 11227923;
  pipe.fd = 8;
  WaitDependency socket;
  socket.kind = WaitDependency::Kind::socket;
  socket.inode = 300;
  socket.peer = 301;
  socket.fd = 4;
  w.dependencies = {child, pipe, socket, WaitDependency{}};
  w.threads = {"thread 12 (cat): read() on fd 8, no timeout", "thread 13 (cat): waitpid() on fd 11 (child 4242), no timeout"};
  const std::string text = format_process_waits(w);
  EXPECT_EQ(text,
            "child 4242\npipe 11227923 8\nsocket 300 301 4\nother\n"
            "| thread 12 (cat): read() on fd 8, no timeout\n"
            "| thread 13 (cat): waitpid() on fd 11 (child 4242), no timeout\n");
  EXPECT_EQ(parse_process_waits(text), w);
}

TEST(ProcessWaits, ALineBreakInAThreadsWordsStaysOnItsLine) {
  ProcessWaits w;
  w.threads = {"thread 1 (a\nb): pause(), no timeout"};
  const auto back = parse_process_waits(format_process_waits(w));
  ASSERT_TRUE(back);
  ASSERT_EQ(back->threads.size(), 1u);
  EXPECT_EQ(back->threads[0], "thread 1 (a b): pause(), no timeout");
}

TEST(ProcessWaits, AFileCutShortOrWithAnUnknownLineIsRefused) {
  EXPECT_FALSE(parse_process_waits("child 12"));  // no line end: cut short
  EXPECT_FALSE(parse_process_waits("child\n"));
  EXPECT_FALSE(parse_process_waits("child 0\n"));
  EXPECT_FALSE(parse_process_waits("child 12x\n"));
  EXPECT_FALSE(parse_process_waits("pipe 5\n"));
  EXPECT_FALSE(parse_process_waits("socket 5 3\n"));
  EXPECT_FALSE(parse_process_waits("fifo 5 3\n"));
  EXPECT_TRUE(parse_process_waits(""));  // nothing waited on: an empty list
}

TEST(ProcessWaits, TheDirectoryIsBesideTheReportFile) {
  EXPECT_EQ(run_waits_directory("/tmp/l6470emu-run-report-abc"), "/tmp/l6470emu-run-report-abc.waits");
}

}  // namespace
}  // namespace l6470emu
