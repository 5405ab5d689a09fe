// umockdev .ioctl export (spi/export_umockdev.cpp): the text umockdev reads, a round trip
// through our importer, and Debian's umockdev-run replaying an exported file to a real
// spidev client (SPI_IOC_MESSAGE only, as umockdev's built-in SPI replay requires).
#include <gtest/gtest.h>

#include <sstream>

#include "spi/export_umockdev.hpp"
#include "spi/trace_import.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using Bytes = std::vector<std::uint8_t>;
using test::RecordedSession;

Bytes bytes(std::span<const std::uint8_t> s) { return Bytes(s.begin(), s.end()); }

Trace session() {
  RecordedSession s(2);
  s.each({0xD0, 0x00, 0x00});
  s.all({{0x38, 0x00, 0x00}, {0x21, 0x00, 0x00, 0x00}});  // GetParam(CONFIG), GetParam(ABS_POS)
  s.rec.set_sw_pin(1, false);
  s.frame({});  // a CS pulse without bytes
  s.each({0xD0, 0x00, 0x00});
  return std::move(s.trace);
}

std::string exported(const Trace& t, UmockdevExportStats* stats = nullptr) {
  std::ostringstream out;
  auto r = t.reader();
  const UmockdevExportStats s = export_umockdev_ioctl(*r, out);
  if (stats) *stats = s;
  return out.str();
}

TEST(UmockdevExport, WritesOneTransferPerFrameAndTheRestAsComments) {
  UmockdevExportStats stats;
  const std::string text = exported(session(), &stats);
  EXPECT_EQ(text.rfind("@DEV /dev/spidev0.0 (SPI)\n", 0), 0u);
  EXPECT_NE(text.find("\nTW d0d0\n R 0000\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nTW 0000\n R 7c7c\n"), std::string::npos) << text;
  EXPECT_NE(text.find("# 0.00"), std::string::npos);  // pin events as comments
  EXPECT_NE(text.find("pin 1 SW 0"), std::string::npos);
  EXPECT_NE(text.find("# empty CS frame at "), std::string::npos);
  EXPECT_EQ(stats.frames, 10u);
  EXPECT_EQ(stats.empty_frames, 1u);
}

TEST(UmockdevExport, RoundTripsThroughTheImporter) {
  const Trace t = session();
  const Trace back = import_umockdev_ioctl(exported(t), "x.ioctl");
  std::size_t j = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const TraceEvent e = t[i];
    if (e.kind != TraceEventKind::frame || e.mosi.empty()) continue;
    ASSERT_LT(j, back.size());
    EXPECT_EQ(bytes(back[j].mosi), bytes(e.mosi));
    EXPECT_EQ(bytes(back[j].miso), bytes(e.miso));
    ++j;
  }
  EXPECT_EQ(j, back.size());
}

TEST(UmockdevExport, ReplaysUnderUmockdevRunToASpidevClient) {
  if (!test::have_program("umockdev-run")) GTEST_SKIP() << "umockdev-run not installed (Debian package umockdev)";
  const Trace t = session();
  test::TempDir dir;
  const std::string ioctl = dir.write("session.ioctl", exported(t));
  // What the client sends and expects, frame by frame.
  std::string frames, wrong;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const TraceEvent e = t[i];
    if (e.kind != TraceEventKind::frame || e.mosi.empty()) continue;
    std::string tx, rx;
    for (auto b : e.mosi) tx += hex_bytes(std::span(&b, 1));
    for (auto b : e.miso) rx += hex_bytes(std::span(&b, 1));
    frames += tx + " " + rx + "\n";
  }
  const std::string list = dir.write("frames.txt", frames);
  const std::string cmd = "umockdev-run -d " + test::fixture_path("spidev0.0.umockdev") + " -i /dev/spidev0.0=" + ioctl +
                          " -- " + L6470EMU_SPIDEV_CLIENT + " /dev/spidev0.0 ";
  const test::RunResult ok = test::run_command(cmd + list);
  EXPECT_EQ(ok.status, 0) << ok.out;
  EXPECT_NE(ok.out.find("10 frames replayed"), std::string::npos) << ok.out;

  // umockdev checks what is written: a client sending other bytes is refused.
  wrong = frames;
  wrong.replace(wrong.find("0000 7C7C"), 4, "0001");
  const test::RunResult bad = test::run_command(cmd + dir.write("wrong.txt", wrong));
  EXPECT_EQ(bad.status, 1) << bad.out;
  EXPECT_NE(bad.out.find("frame 2 (0001): SPI_IOC_MESSAGE: No message of desired type"), std::string::npos) << bad.out;
}

// What docs/trace-format.md says umockdev 0.17's SPI replay lacks, kept true: only
// SPI_IOC_MESSAGE, read and write are answered; the mode/bits/speed ioctls fail with ENOTTY, so
// py-spidev (which reads them in open()) cannot open the device, while a client that does not
// ask replays fine.
TEST(UmockdevExport, AnswersOnlyMessagesSoPySpidevCannotOpen) {
  if (!test::have_program("umockdev-run")) GTEST_SKIP() << "umockdev-run not installed (Debian package umockdev)";
  const Trace t = session();
  test::TempDir dir;
  const std::string ioctl = dir.write("session.ioctl", exported(t));
  std::string frames;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const TraceEvent e = t[i];
    if (e.kind != TraceEventKind::frame || e.mosi.empty()) continue;
    std::string tx, rx;
    for (auto b : e.mosi) tx += hex_bytes(std::span(&b, 1));
    for (auto b : e.miso) rx += hex_bytes(std::span(&b, 1));
    frames += tx + " " + rx + "\n";
  }
  const std::string run = "umockdev-run -d " + test::fixture_path("spidev0.0.umockdev") + " -i /dev/spidev0.0=" + ioctl + " -- ";
  const test::RunResult c = test::run_command(run + L6470EMU_SPIDEV_CLIENT + " /dev/spidev0.0 " +
                                              dir.write("frames.txt", frames) + " --ask-mode");
  EXPECT_EQ(c.status, 0) << c.out;
  EXPECT_NE(c.out.find("SPI_IOC_RD_MODE: Inappropriate ioctl for device\n"
                       "SPI_IOC_RD_BITS_PER_WORD: Inappropriate ioctl for device\n"
                       "SPI_IOC_RD_MAX_SPEED_HZ: Inappropriate ioctl for device\n"),
            std::string::npos)
      << c.out;
  EXPECT_NE(c.out.find("10 frames replayed"), std::string::npos) << c.out;

  if (std::system("/usr/bin/python3 -c 'import spidev' 2>/dev/null") != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no spidev (Debian package python3-spidev)";
  const test::RunResult py = test::run_command(
      run + "/usr/bin/python3 -c \"import errno, spidev\n"
            "try:\n    spidev.SpiDev().open(0, 0)\nexcept OSError as e:\n"
            "    print('open failed:', errno.errorcode[e.errno])\nelse:\n    print('opened')\"");
  EXPECT_EQ(py.out, "open failed: ENOTTY\n") << py.out;
}

}  // namespace
}  // namespace l6470emu
