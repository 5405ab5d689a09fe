// VCD export (spi/export_vcd.cpp, daisychain/emulated_vcd.cpp): the file's structure, SPI
// mode 3 bit by bit, and Debian's sigrok-cli decoding an exported VCD back to the same bytes.
#include <gtest/gtest.h>

#include <sstream>

#include "daisychain/emulated_vcd.hpp"
#include "spi/export_vcd.hpp"
#include "spi/trace_import.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using Bytes = std::vector<std::uint8_t>;
using test::RecordedSession;

Bytes bytes(std::span<const std::uint8_t> s) { return Bytes(s.begin(), s.end()); }

/// Two chips: clear the UVLO flags, move chip 1, read positions, a switch event on chip 0.
Trace session() {
  RecordedSession s(2);
  s.wait_ms(1);
  s.each({0xD0, 0x00, 0x00});
  s.all({{0x00, 0x00, 0x00, 0x00}, {0x41, 0x00, 0x01, 0x00}});  // chip 1: Move(FWD, 256)
  s.wait_ms(2);
  s.rec.set_sw_pin(0, false);
  s.each({0x21, 0x00, 0x00, 0x00});
  s.wait_ms(1);
  s.each({0xD0, 0x00, 0x00});
  return std::move(s.trace);
}

TEST(VcdWriter, DeclaresWiresAndNumbersThenWritesChangesInTimeOrder) {
  std::ostringstream out;
  {
    VcdWriter w(out, 10);
    const int a = w.wire("top", "A", true);
    const int n = w.number("top", "POS", -3);
    w.change(100, a, 0);
    w.change(100, n, 7);
    w.change(150, a, 0);  // unchanged: not written
    w.unknown(200, a);
    w.finish(300);
  }
  EXPECT_EQ(out.str(),
            "$version l6470emu $end\n$timescale 10 ns $end\n$scope module top $end\n$var wire 1 ! A $end\n"
            "$var real 64 \" POS $end\n$upscope $end\n$enddefinitions $end\n#0\n$dumpvars\n1!\nr-3 \"\n$end\n"
            "#10\n0!\nr7 \"\n#20\nx!\n#30\n");
}

/// A stream buffer that keeps nothing and remembers the longest piece it was handed at once.
class LargestWrite : public std::streambuf {
 public:
  std::streamsize largest = 0, total = 0;

 protected:
  std::streamsize xsputn(const char*, std::streamsize n) override {
    largest = std::max(largest, n);
    total += n;
    return n;
  }
  int_type overflow(int_type c) override {
    largest = std::max<std::streamsize>(largest, 1);
    ++total;
    return traits_type::not_eof(c);
  }
};

TEST(VcdWriter, HoldsAtMost64KiBOfChangesHoweverManyFallAtOneTime) {
  LargestWrite sink;
  std::ostream out(&sink);
  VcdWriter w(out, 10);
  const int a = w.wire("top", "A", false);
  // A million changes at one time (times that go back are written at the last one).
  w.change(1000, a, 1);
  for (int i = 0; i < 1'000'000; ++i) w.change(500, a, i % 2 == 0 ? 0 : 1);
  w.finish(2000);
  EXPECT_GT(sink.total, 3'000'000);
  EXPECT_LE(sink.largest, 65536 + 64);
}

TEST(VcdWriter, StopsAtTheFirstFailedWrite) {
  std::ostringstream out;
  VcdWriter w(out, 10);
  const int a = w.wire("top", "A", false);
  w.change(10, a, 1);
  out.setstate(std::ios::badbit);
  EXPECT_THROW(
      {
        for (int i = 0; i < 1'000'000; ++i) w.change(20 + 10 * static_cast<std::uint64_t>(i), a, i % 2);
      },
      std::ios_base::failure);
}

TEST(VcdExport, ReadsATraceAsPassesSideBySideAndWritesWhatItWroteFromMemory) {
  // The streamed export (three passes of a reader) writes the same bytes as from a Trace.
  const Trace t = session();
  std::ostringstream from_memory, streamed;
  export_vcd(t, from_memory);
  int passes = 0;
  export_vcd(
      [&] {
        ++passes;
        return t.reader();
      },
      streamed);
  EXPECT_EQ(streamed.str(), from_memory.str());
  EXPECT_EQ(passes, 3);
}

TEST(SpiVcdWaveform, DrawsAFrameInMode3WithEightClocksPerByte) {
  std::ostringstream out;
  VcdWriter w(out, 1);
  SpiVcdWaveform spi(w);
  const Bytes mosi{0xA5}, miso{0x3C};
  TraceEvent f;
  f.tick = 4;
  f.duration = 18;  // 4.5 µs: 18 half periods of 250 ns
  f.mosi = mosi;
  f.miso = miso;
  const std::uint64_t end = spi.draw(f, 0);
  w.finish(end + 100);
  EXPECT_EQ(end, 1000u + 4500u);
  const std::string v = out.str();
  // CS falls at 1 µs; SCK falls 250 ns later with MOSI's MSB (1) and MISO's MSB (0) set.
  EXPECT_NE(v.find("#1000\n0!\n#1250\n0\"\n1#\n#1500\n1\"\n"), std::string::npos) << v;
  // 8 rising edges of SCK.
  std::size_t rises = 0;
  for (std::size_t p = v.find("1\"\n"); p != std::string::npos; p = v.find("1\"\n", p + 1)) ++rises;
  EXPECT_EQ(rises, 8u + 1u);  // + the initial value
}

TEST(VcdExport, CarriesTheTracesPinsAndEmulatedChipsCarryPositions) {
  const Trace t = session();
  std::ostringstream plain, emulated;
  export_vcd(t, plain);
  EXPECT_NE(plain.str().find("$scope module chip0 $end"), std::string::npos);
  EXPECT_NE(plain.str().find(" SW $end"), std::string::npos);
  Chain chain(2);
  export_emulated_vcd(t, chain, emulated);
  const std::string v = emulated.str();
  for (const char* name : {" BUSY $end", " FLAG $end", " SW $end", " STCK $end", " STBY $end", " ABS_POS $end",
                           " COIL_A $end", " COIL_B $end"})
    EXPECT_NE(v.find(name), std::string::npos) << name;
  EXPECT_NE(v.find("r256 "), std::string::npos);  // chip 1 ends its Move at ABS_POS 256
}

TEST(VcdExport, DecodesBackToTheSameBytesWithSigrokCli) {
  if (!test::have_program("sigrok-cli")) GTEST_SKIP() << "sigrok-cli not installed (Debian package sigrok-cli)";
  const Trace t = session();
  test::TempDir dir;
  std::ostringstream vcd;
  Chain chain(2);
  export_emulated_vcd(t, chain, vcd);
  const std::string path = dir.write("session.vcd", vcd.str());
  const test::RunResult r = test::run_command(
      "sigrok-cli -I vcd -i " + path +
      " -P spi:clk=SCK:mosi=MOSI:miso=MISO:cs=CS:cpol=1:cpha=1 -A spi=mosi-transfer:miso-transfer --protocol-decoder-jsontrace");
  ASSERT_EQ(r.status, 0) << r.out;
  const Trace back = import_sigrok_json(r.out, "sigrok-cli output");
  ASSERT_EQ(back.frame_count(), t.frame_count());
  std::size_t j = 0;
  Tick first = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const TraceEvent e = t[i];
    if (e.kind != TraceEventKind::frame) continue;
    if (j == 0) first = e.tick;
    const TraceEvent b = back[j++];
    EXPECT_EQ(bytes(b.mosi), bytes(e.mosi)) << "frame " << j;
    EXPECT_EQ(bytes(b.miso), bytes(e.miso)) << "frame " << j;
    EXPECT_NEAR(static_cast<double>(b.tick), static_cast<double>(e.tick - first), 1.0) << "frame " << j;
  }
}

}  // namespace
}  // namespace l6470emu
