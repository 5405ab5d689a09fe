// The native format's `wire` lines (version 3, spi/trace_wire.hpp): written before a frame whose
// host settings differ from the frame's before, read back onto every frame after them (repeated
// frames too), kept by an in-memory Trace, refused in older versions and when malformed.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using test::frame_at;
using Bytes = std::vector<std::uint8_t>;

std::string error_of(const std::string& text) {
  try {
    read_native_trace(text, "w.trace");
  } catch (const TraceError& e) {
    return e.what();
  }
  return "(no error)";
}

TraceWire wire(std::uint8_t mode, bool lsb, std::uint8_t bits, std::uint32_t hz, bool timed) {
  TraceWire w;
  w.known = true;
  w.mode = mode;
  w.lsb_first = lsb;
  w.bits_per_word = bits;
  w.speed_hz = hz;
  w.deselect_timed = timed;
  return w;
}

/// The lines of `text` after the header and the numbering comment.
std::string body(const std::string& text) {
  const std::string numbering = std::string(kNativeTraceNumbering) + "\n";
  return text.substr(text.find(numbering) + numbering.size());
}

TEST(TraceWire, AWireLineIsWrittenBeforeEachFrameWhoseSettingsDifferAndReadBackOntoEveryFrame) {
  const Bytes d0{0xD0}, z{0x00}, a{0x00}, fc{0xFC};
  Trace t;
  TraceEvent f = frame_at(0, 7, d0, a);
  f.wire = wire(0, false, 8, 5'000'000, true);
  t.write(f);
  f = frame_at(10, 7, z, fc);
  f.wire = wire(0, false, 8, 5'000'000, true);
  t.write(f);
  f = frame_at(20, 14, z, a);
  f.wire = wire(2, true, 16, 400'000, false);
  t.write(f);
  f = frame_at(40, 7, z, a);  // a frame that says nothing: mode 3 again
  t.write(f);
  const std::string text = to_native_text(t);
  EXPECT_EQ(text.rfind("l6470emu-trace 3\n", 0), 0u);
  EXPECT_EQ(body(text),
            "0.00000000 wire mode=0 order=msb bits=8 speed=5000000 deselect=timed\n"
            "0.00000000 frame 1.75us D0 | 00\n"
            "0.00000250 frame 1.75us 00 | FC\n"
            "0.00000500 wire mode=2 order=lsb bits=16 speed=400000 deselect=untimed\n"
            "0.00000500 frame 3.50us 00 | 00\n"
            "0.00001000 wire mode=3 order=msb bits=8 speed=0 deselect=untimed\n"
            "0.00001000 frame 1.75us 00 | 00\n");
  const Trace back = read_native_trace(text, "w.trace");
  ASSERT_EQ(back.size(), 4u);
  EXPECT_EQ(back[0].wire, wire(0, false, 8, 5'000'000, true));
  EXPECT_EQ(back[1].wire, wire(0, false, 8, 5'000'000, true));
  EXPECT_EQ(back[2].wire, wire(2, true, 16, 400'000, false));
  EXPECT_TRUE(back[3].wire.known);  // said explicitly now, with the defaults
  EXPECT_TRUE(back[3].wire.same_as(TraceWire{}));
  EXPECT_EQ(to_native_text(back), text);
}

TEST(TraceWire, FramesOfAnOlderFileOrWithoutAWireLineHaveNoKnownWire) {
  const Trace old = read_native_trace("l6470emu-trace 2\n0 frame D0 | 00\n", "old.trace");
  EXPECT_FALSE(old[0].wire.known);
  EXPECT_EQ(old[0].wire.mode, 3);
  const Bytes d0{0xD0}, z{0x00};
  Trace t;
  t.write(frame_at(0, 7, d0, z));
  EXPECT_EQ(body(to_native_text(t)), "0.00000000 frame 1.75us D0 | 00\n");
}

TEST(TraceWire, RepeatedFramesHaveTheWireOfTheirGroupAndAWireChangeEndsTheRun) {
  const Bytes d0{0xD0}, z{0x00};
  Trace t;
  for (int i = 0; i < 20; ++i) {
    TraceEvent f = frame_at(static_cast<Tick>(i) * 100, 7, i < 10 ? d0 : z, z);
    f.wire = wire(i < 10 ? 0 : 1, false, 8, 1'000'000, true);
    t.write(f);
  }
  const std::string text = to_native_text(t, true);
  EXPECT_NE(text.find("0.00022500 repeat 1 frame 8 times every 25.00us\n"), std::string::npos) << text;
  EXPECT_NE(text.find("0.00025000 wire mode=1 order=msb bits=8 speed=1000000 deselect=timed\n"), std::string::npos) << text;
  const Trace back = read_native_trace(text, "w.trace");
  ASSERT_EQ(back.size(), 20u);
  for (std::size_t i = 0; i < 20; ++i) {
    EXPECT_EQ(back[i].wire.mode, i < 10 ? 0 : 1) << i;
    EXPECT_EQ(back[i].tick, i * 100) << i;
  }
}

TEST(TraceWire, AWireLineNeedsVersionThreeAndWellFormedFields) {
  const std::string head = "l6470emu-trace 3\n";
  const std::string form = " (expected 'TIME wire mode=0..3 order=msb|lsb bits=1..32 speed=HZ deselect=timed|untimed')";
  EXPECT_EQ(error_of("l6470emu-trace 2\n0 wire mode=0 order=msb bits=8 speed=0 deselect=timed\n"),
            "w.trace:2: 'wire' lines need format version 3 (the first line says 2)");
  EXPECT_EQ(error_of(head + "0 wire mode=4 order=msb bits=8 speed=0 deselect=timed\n"),
            "w.trace:2: wire: mode \"4\" is not an SPI mode (0..3)" + form);
  EXPECT_EQ(error_of(head + "0 wire mode=0 order=up bits=8 speed=0 deselect=timed\n"),
            "w.trace:2: wire: order \"up\" is not msb or lsb" + form);
  EXPECT_EQ(error_of(head + "0 wire mode=0 order=msb bits=0 speed=0 deselect=timed\n"),
            "w.trace:2: wire: bits \"0\" is not a word size (1..32 bits)" + form);
  EXPECT_EQ(error_of(head + "0 wire mode=0 order=msb bits=8 speed=99999999999 deselect=timed\n"),
            "w.trace:2: wire: speed \"99999999999\" is not a clock in Hz (0..1000000000; 0 = not known)" + form);
  EXPECT_EQ(error_of(head + "0 wire mode=0 order=msb bits=8 speed=0 deselect=soon\n"),
            "w.trace:2: wire: deselect \"soon\" is not timed or untimed" + form);
  EXPECT_EQ(error_of(head + "0 wire mode=0 bits=8\n"), "w.trace:2: wire: \"bits=8\" where order=... belongs" + form);
  EXPECT_EQ(error_of(head + "0 wire mode=0\n"), "w.trace:2: wire: order=... is missing" + form);
  EXPECT_EQ(error_of(head + "0 wire mode=0 order=msb bits=8 speed=0 deselect=timed x\n"),
            "w.trace:2: too many fields in the wire line" + form);
  EXPECT_EQ(error_of(head + "1 frame D0\n0.5 wire mode=0 order=msb bits=8 speed=0 deselect=timed\n"),
            "w.trace:3: time 0.5 s goes backwards (the previous event was at 1.00000000 s)");
  // Between a group of frames and its repeat line: the repeat has nothing to repeat.
  EXPECT_NE(error_of(head + "0 frame D0\n0.001 wire mode=0 order=msb bits=8 speed=0 deselect=timed\n"
                            "0.002 repeat 1 frame 1 time every 1000.00us\n")
                .find("w.trace:4: repeat: there are 0 frame lines to repeat"),
            std::string::npos);
}

}  // namespace
}  // namespace l6470emu
