// ChainTraceRecorder's file names (board/trace_recorder.hpp): one file per chain, the chain's
// name before the extension, and ".gz" kept last so the recording stays compressed.
#include <gtest/gtest.h>

#include "board/trace_recorder.hpp"

namespace l6470emu {
namespace {

TEST(TracePathForChain, PutsTheChainNameBeforeTheExtensionAndKeepsGzLast) {
  EXPECT_EQ(trace_path_for_chain("run.trace", "spidev0.1", 1), "run.trace");
  EXPECT_EQ(trace_path_for_chain("run.trace", "spidev0.1", 2), "run.spidev0.1.trace");
  EXPECT_EQ(trace_path_for_chain("run.trace.gz", "spidev0.1", 2), "run.spidev0.1.trace.gz");
  EXPECT_EQ(trace_path_for_chain("/tmp/d.x/run.gz", "spidev0.1", 2), "/tmp/d.x/run.spidev0.1.gz");
  EXPECT_EQ(trace_path_for_chain("run", "spidev0.1", 2), "run.spidev0.1");
}

}  // namespace
}  // namespace l6470emu
