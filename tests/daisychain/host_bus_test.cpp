// ChainHost over another bus face (daisychain/host.hpp): commands sent through a
// RecordingChain are recorded frame by frame and replay clean against a fresh chain.
#include <gtest/gtest.h>

#include "daisychain/host.hpp"
#include "daisychain/recording_chain.hpp"
#include "daisychain/replay.hpp"

namespace l6470emu {
namespace {

TEST(ChainHostOverABus, SendsEveryFrameThroughTheBusItWasGiven) {
  Chain chain(2);
  Trace trace;
  RecordingChain rec(chain, trace, RecordOptions{.observe_outputs = false, .board = {}});
  ChainHost host(chain, rec);
  EXPECT_EQ(host.get_status(1), 0x7C03);  // three frames: D0, then the two answer bytes
  host.move(1, true, 3200);               // four frames
  EXPECT_EQ(rec.frames_recorded(), 7u);
  host.wait_ms(500);
  EXPECT_EQ(host.get_param(1, Reg::ABS_POS), 3200u);
  EXPECT_EQ(rec.frames_recorded(), 11u);
  EXPECT_EQ(chain.now(), rec.now());
}

TEST(ChainHostOverABus, WhatItRecordedReplaysWithoutADivergence) {
  Chain chain(3);
  Trace trace;
  RecordingChain rec(chain, trace);
  ChainHost host(chain, rec);
  host.set_param(0, Reg::MAX_SPEED, 0x20);
  host.move(0, false, 1000);
  host.wait_ms(200);
  rec.observe_outputs();
  host.get_status(0);
  host.get_param(0, Reg::ABS_POS);

  Chain fresh(3);
  auto reader = trace.reader();
  const ReplayResult r = replay_trace(*reader, fresh);
  EXPECT_TRUE(r.matched());
  EXPECT_EQ(r.frames, trace.frame_count());
  EXPECT_GT(r.pin_checks, 0u);
}

}  // namespace
}  // namespace l6470emu
