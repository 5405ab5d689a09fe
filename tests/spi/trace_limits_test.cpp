// The native format's limits, one constant on both sides: whatever the writer writes (times and
// periods up to 10^12 s, frames up to 1 MiB, repeat lines), its reader reads back; what the
// reader would refuse, the writer refuses to write; and the frame bound of every reader.
#include <gtest/gtest.h>

#include <sstream>

#include "spi/trace_import.hpp"
#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using test::frame_at;
using Bytes = std::vector<std::uint8_t>;

std::string written(const Trace& t, bool compact) {
  std::ostringstream out;
  NativeTraceWriter w(out, NativeWriteOptions{false, compact}, "out");
  w.write_header(t.header);
  for (std::size_t i = 0; i < t.size(); ++i) w.write(t[i]);
  w.finish();
  return out.str();
}

void expect_same(const Trace& a, const Trace& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].tick, b[i].tick) << i;
    EXPECT_EQ(a[i].duration, b[i].duration) << i;
    EXPECT_EQ(Bytes(a[i].mosi.begin(), a[i].mosi.end()), Bytes(b[i].mosi.begin(), b[i].mosi.end())) << i;
  }
}

TEST(NativeTraceLimits, WhatTheWriterWritesAtTheExtremesTheReaderReadsBack) {
  // A host polling every 2.5·10^11 s (the writer collapses it into repeat lines with that
  // period), a frame lasting 10^11 s, and the last frame ending exactly at 10^12 s.
  const Tick period = kMaxNativeTraceTick / 4;
  Trace t;
  t.header.chain = "1";
  const Bytes d0{0xD0}, st{0x7C};
  for (Tick k = 0; k < 3; ++k) t.write(frame_at(k * period, 7, d0, st));
  t.write(frame_at(3 * period - kTicksPerSecond * 100'000'000'000 + 8, kTicksPerSecond * 100'000'000'000 - 8 - 7,
                   d0, st));
  t.write(frame_at(kMaxNativeTraceTick - 7, 7, d0, st));
  for (const bool compact : {true, false}) {
    const std::string text = written(t, compact);
    if (compact) {
      EXPECT_NE(text.find(" repeat 1 frame 1 time every 250000000000000000.00us\n"), std::string::npos) << text;
    }
    expect_same(t, read_native_trace(text, "extreme.trace"));
  }
}

TEST(NativeTraceLimits, TheWriterRefusesWhatItsReaderWouldRefuseNamingWhereItWrites) {
  const Bytes d0{0xD0};
  std::ostringstream out;
  NativeTraceWriter w(out, NativeWriteOptions{false, true}, "run.trace");
  w.write(frame_at(0, 7, d0, {}));
  try {
    w.write(frame_at(kMaxNativeTraceTick - 6, 7, d0, {}));  // ends 1 tick past 10^12 s
    FAIL() << "written";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "run.trace: an event at 999999999999.99999850 s lasting 1.75 us is beyond 10^12 s, the latest time a "
              "native trace holds");
  }
  EXPECT_THROW(w.write(frame_at(kMaxNativeTraceTick + 1, 0, d0, {})), std::runtime_error);
  EXPECT_THROW(w.write(frame_at(8, 0, Bytes(kMaxTraceFrameBytes + 1), {})), std::runtime_error);
  w.write(frame_at(16, 0, Bytes(kMaxTraceFrameBytes), {}));  // the longest frame is fine
  w.finish();
  EXPECT_EQ(read_native_trace(out.str(), "run.trace").size(), 2u);
}

TEST(NativeTraceLimits, TheReaderRefusesTimesAndFramesPastTheLimitsWithTheLine) {
  auto error_of = [](const std::string& body, std::uint64_t max_frames = kDefaultMaxTraceFrames) {
    try {
      read_native_trace("l6470emu-trace 1\n" + body, "t.trace", max_frames);
    } catch (const TraceError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(error_of("1000000000000.00000000 frame 00\n"), "(no error)");
  EXPECT_EQ(error_of("1000000000000.00000025 frame 00\n"),
            "t.trace:2: timestamp \"1000000000000.00000025\" is too large (at most 10^12 s)");
  EXPECT_EQ(error_of("999999999999.99999999 frame 1.00us 00\n"),
            "t.trace:2: frame at 999999999999.99999999 s ends after 10^12 s (the latest time a native trace holds)");
  EXPECT_EQ(error_of("0 frame 1000000000000000001.00us 00\n"),
            "t.trace:2: frame duration \"1000000000000000001.00us\" is too long (at most 10^12 s)");
  EXPECT_EQ(error_of("0 frame 00\n0.00000100 frame 00\n0.00000200 frame 00\n"), "(no error)");
  EXPECT_EQ(error_of("0 frame 00\n0.00000100 frame 00\n0.00000200 frame 00\n", 2),
            "t.trace:4: the trace holds more than 2 frames, the limit (raise it with --max-frames N, or max_frames=N "
            "in Python; 0 = no limit)");
  std::string huge = "0 frame";
  for (std::size_t i = 0; i <= kMaxTraceFrameBytes; ++i) huge += " 00";
  EXPECT_EQ(error_of(huge + "\n"), "t.trace:2: a frame of 1048577 bytes or more: a trace frame holds at most 1048576 bytes");
}

TEST(ImportFrameLimits, EveryImporterRefusesAFrameOrATraceTooLargeNamingTheLine) {
  ImportOptions two;
  two.max_frames = 2;
  auto error_of = [](auto&& import) {
    try {
      import();
    } catch (const TraceError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  std::string csv = "name,type,start_time,duration,\"mosi\",\"miso\"\n";
  for (int i = 1; i <= 3; ++i)
    csv += "\"SPI\",\"result\",0." + std::to_string(i) + ",1e-06,0xD0,0x00\n";  // no enable: a frame per byte
  EXPECT_EQ(error_of([&] { return import_saleae_csv(csv, "c.csv", two); }),
            "c.csv:4: the trace holds more than 2 frames, the limit (raise it with --max-frames N, or max_frames=N in "
            "Python; 0 = no limit)");
  EXPECT_EQ(error_of([&] { return import_umockdev_ioctl("TW 00\nTW 00\nTW 00\n", "u.ioctl", two); }),
            "u.ioctl:3: the trace holds more than 2 frames, the limit (raise it with --max-frames N, or max_frames=N "
            "in Python; 0 = no limit)");
  std::string ftrace;
  for (int i = 1; i <= 3; ++i)
    ftrace += " p-1 [000] ..... 1.00000" + std::to_string(i) +
              ": spi_transfer_stop: spi0.0 00000000deadbeef len=1 tx=[00] rx=[00]\n";
  EXPECT_EQ(error_of([&] { return import_ftrace(ftrace, "f.txt", two); }).substr(0, 46),
            "f.txt:3: the trace holds more than 2 frames, t");
  std::string json = "{\"traceEvents\": [\n";
  for (int i = 1; i <= 3; ++i)
    json += std::string(i > 1 ? ",\n" : "") + "{\"ph\": \"B\", \"ts\": " + std::to_string(i * 10) +
            ", \"pid\": \"spi-1\", \"tid\": \"MOSI data\", \"name\": \"D0\"},\n{\"ph\": \"E\", \"ts\": " +
            std::to_string(i * 10 + 2) + ", \"pid\": \"spi-1\", \"tid\": \"MOSI data\", \"name\": \"D0\"}";
  json += "\n]}\n";
  EXPECT_EQ(error_of([&] { return import_sigrok_json(json, "s.json", two); }).substr(0, 47),
            "s.json:6: the trace holds more than 2 frames, t");
  EXPECT_EQ(import_sigrok_json(json, "s.json").frame_count(), 3u);
}

}  // namespace
}  // namespace l6470emu
