// Small files that ask for huge work or memory, given to the trace subcommands as a user would:
// each is refused with one line naming the file and line, and the l6470emu process's peak
// resident memory (getrusage of the child, ru_maxrss) stays far below what the file would
// unpack to. No timed assertion: a trace that asked for hours and was not refused would hit
// ctest's time limit instead.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "spi/trace_file.hpp"
#include "spi/trace_native.hpp"
#include "support/test_support.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using test::fixture_path;
using test::TempDir;

/// What a run of the l6470emu program did, with its peak resident memory.
struct Measured {
  int status = -1;       ///< exit status (-1: killed)
  std::string out;       ///< standard output and error, merged
  long max_rss_kb = 0;   ///< ru_maxrss of the process
};

/// Runs l6470emu with `args`, its address space and the size of the files it writes limited
/// (past `file_size`, a write fails with EFBIG instead of killing it with SIGXFSZ).
Measured run_measured(const std::vector<std::string>& args, rlim_t address_space = RLIM_INFINITY,
                      rlim_t file_size = RLIM_INFINITY) {
  TempDir dir;
  const std::string out_path = dir.file("out.txt");
  std::vector<std::string> argv = {L6470EMU_BINARY};
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<char*> cargv;
  for (std::string& a : argv) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    if (address_space != RLIM_INFINITY) {
      const rlimit limit{address_space, address_space};
      setrlimit(RLIMIT_AS, &limit);
    }
    if (file_size != RLIM_INFINITY) {
      const rlimit limit{file_size, file_size};
      setrlimit(RLIMIT_FSIZE, &limit);
      signal(SIGXFSZ, SIG_IGN);
    }
    const int fd = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    dup2(fd, 1);
    dup2(fd, 2);
    execv(cargv[0], cargv.data());
    _exit(127);
  }
  Measured m;
  int st = 0;
  rusage usage{};
  if (wait4(pid, &st, 0, &usage) != pid) return m;
  m.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  m.max_rss_kb = usage.ru_maxrss;
  m.out = test::read_text(out_path);
  return m;
}

/// Writes `text` gzip-compressed to `path` (a name ending in .gz).
void write_gz(const std::string& path, const std::string& text) {
  TraceFileWriter w(path);
  w.write(text);
  w.close();
}

/// Generously above what the program needs for these inputs (~10 MB), far below what any of
/// them unpacks to (100 MB and more). A sanitizer build's program keeps freed memory in
/// quarantine and maps shadow memory: its peak says nothing there, and is not checked.
#if defined(L6470EMU_TEST_ASAN)
constexpr long kBoundedKb = std::numeric_limits<long>::max();
#else
constexpr long kBoundedKb = 64 * 1024;
#endif

const std::string kFrameLimit = "a trace frame holds at most 1048576 bytes";

TEST(TraceBombs, ANativeRepeatLineAskingForATrillionFramesIsRefusedAtOnceByReplayDecodeAndConvert) {
  TempDir dir;
  const std::string bomb =
      dir.write("bomb.trace", "l6470emu-trace 1\nchain L6470\n0.00000000 frame 0.25us 00 | 00\n"
                              "1000000.00000000 repeat 1 frame 1000000000000 times every 1.00us\n");
  ASSERT_LT(test::read_text(bomb).size(), 160u);
  const std::string why = bomb + ":4: repeat: 1000000000000 repetitions of 1 frame make the trace 1000000000001 "
                                 "frames long: more than 10000000 frames, the limit (raise it with --max-frames N, "
                                 "or max_frames=N in Python; 0 = no limit)\n";
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"replay", bomb}, {"decode", bomb}, {"convert", bomb, "-o", "-", "--expand"},
        {"convert", bomb, "-o", dir.file("out.trace")}, {"convert", bomb, "-o", dir.file("out.vcd")},
        {"replay", "--max-frames", "999999999999", bomb}}) {
    const Measured m = run_measured(args);
    EXPECT_EQ(m.status, 2) << args[0] << "\n" << m.out;
    const std::string expected =
        args.size() > 2 && args[1] == "--max-frames"
            ? bomb + ":4: repeat: 1000000000000 repetitions of 1 frame make the trace 1000000000001 frames long: "
                     "more than 999999999999 frames, the limit (raise it with --max-frames N, or max_frames=N in "
                     "Python; 0 = no limit)\n"
            : why;
    EXPECT_NE(m.out.find("l6470emu " + args[0] + ": " + expected), std::string::npos) << m.out;
    EXPECT_LT(m.max_rss_kb, kBoundedKb);
  }
}

// The finding (issue 35, 7): 6 KB of gzip, one 1 MiB frame on 256 chips repeated 1000 times;
// `convert` to VCD held 2.1 GB (the whole trace in memory) and would have written ~240 GB.
const std::string kMebibyteFrames = "mebibyte_frame_repeated.trace.gz";
/// The address space a conversion of it is given (a sanitizer build's program cannot run under a limit).
#if defined(L6470EMU_TEST_ASAN)
constexpr rlim_t kConvertAddressSpace = RLIM_INFINITY;
#else
constexpr rlim_t kConvertAddressSpace = 512u << 20;
#endif

TEST(TraceBombs, AConversionThatWouldPassTheOutputLimitIsRefusedFromTheTracesCountsBeforeItWritesAByte) {
  TempDir dir;
  const std::string in = fixture_path(kMebibyteFrames);
  ASSERT_LT(test::read_text(in).size(), 8000u);
  const std::string mib = "1001 frames (1001.0 MiB of MOSI) would take ";
  const std::string limit = "more than 1.0 GiB, the output limit (raise it with --max-output ";
  struct Case {
    std::vector<std::string> args;
    std::string out, why;
  };
  for (const Case& c : std::vector<Case>{
           {{"--no-emulation"}, "out.vcd", "VCD of " + mib + "at least 239.8 GiB, " + limit + "240G"},
           {{}, "out.vcd", "VCD of " + mib + "at least 239.8 GiB, " + limit + "240G"},
           {{"--expand"}, "out.trace", "expanded native text of " + mib + "5.9 GiB, " + limit + "6G"},
           {{}, "out.ioctl.gz", "umockdev .ioctl of " + mib + "3.9 GiB, " + limit + "4G"},
           {{"--max-output", "3G"}, "out.ioctl", "umockdev .ioctl of " + mib + "3.9 GiB, more than 3.0 GiB, the output "
                                                "limit (raise it with --max-output 4G"}}) {
    std::vector<std::string> args = {"convert", in, "-o", dir.file(c.out)};
    args.insert(args.end(), c.args.begin(), c.args.end());
    // Limited all the same, so that a program that did not refuse could not fill the disk.
    const Measured m = run_measured(args, kConvertAddressSpace, 64u << 20);
    EXPECT_EQ(m.status, 2) << c.out << "\n" << m.out;
    EXPECT_EQ(m.out, "l6470emu convert: " + dir.file(c.out) + ": " + c.why + "; 0 = no limit)\n");
    EXPECT_NE(access(dir.file(c.out).c_str(), F_OK), 0) << c.out << " was written";
    EXPECT_LT(m.max_rss_kb, kBoundedKb);
  }
  // Compact native text is what the trace is: 12 MB, written.
  const Measured m = run_measured({"convert", in, "-o", dir.file("out.trace")});
  EXPECT_EQ(m.status, 0) << m.out;
  EXPECT_LT(m.max_rss_kb, kBoundedKb);
}

TEST(TraceBombs, ConvertingTheMebibyteFramesWithNoOutputLimitStreamsInBoundedMemoryUpToAFailedWrite) {
#if defined(L6470EMU_TEST_ASAN)
  GTEST_SKIP() << "a sanitizer build's program cannot run under an address-space limit";
#endif
  // Allowed to write, each conversion fills the 32 MiB the files may take and fails there with
  // one line; its memory stays that of one frame, never the trace's gigabytes (the address
  // space it is given is a quarter of the trace).
  TempDir dir;
  const std::string in = fixture_path(kMebibyteFrames);
  for (const std::vector<std::string>& extra : {std::vector<std::string>{"--no-emulation"}, {}}) {
    std::vector<std::string> args = {"convert", in, "-o", dir.file("out.vcd"), "--max-output", "0"};
    args.insert(args.end(), extra.begin(), extra.end());
    const Measured m = run_measured(args, 256u << 20, 32u << 20);
    EXPECT_EQ(m.status, 2) << m.out;
    EXPECT_NE(m.out.find("l6470emu convert: " + dir.file("out.vcd") + ": write failed: File too large\n"),
              std::string::npos)
        << m.out;
    EXPECT_LT(m.max_rss_kb, kBoundedKb);
  }
}

TEST(TraceBombs, MaxFramesRaisesTheLimitAndCountsRepeatedFramesAsTheFramesTheyStandFor) {
  TempDir dir;
  // 2 frames, then 20 repetitions of both: 42 frames.
  const std::string t = dir.write("t.trace", "l6470emu-trace 1\nchain L6470\n0 frame 0.25us 00 | 00\n"
                                             "0.00000100 frame 0.25us 00 | 00\n"
                                             "0.00020100 repeat 2 frames 20 times every 10.00us\n");
  Measured m = run_measured({"replay", "--max-frames", "41", t});
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find(t + ":5: repeat: 20 repetitions of 2 frames make the trace 42 frames long: more than 41 frames"),
            std::string::npos)
      << m.out;
  m = run_measured({"replay", "--max-frames", "42", t});
  EXPECT_EQ(m.status, 0) << m.out;
  EXPECT_NE(m.out.find("42 frames"), std::string::npos) << m.out;
  m = run_measured({"replay", "--max-frames", "1", t});
  EXPECT_NE(m.out.find(t + ":4: the trace holds more than 1 frames, the limit"), std::string::npos) << m.out;
  m = run_measured({"decode", "--max-frames", "-1", t});
  EXPECT_NE(m.status, 0) << m.out;
  EXPECT_NE(m.out.find("--max-frames: '-1' is not a count"), std::string::npos) << m.out;
}

TEST(TraceBombs, ANativeLineThatNeverEndsIsRefusedWithinBoundedMemory) {
  TempDir dir;
  const std::string gz = dir.file("endless.trace.gz");
  write_gz(gz, "l6470emu-trace 1\n0 frame 0.25us " + std::string(100'000'000, '0'));
  const Measured m = run_measured({"replay", gz});
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find(gz + ":2: a line longer than 8388608 bytes"), std::string::npos) << m.out;
  EXPECT_LT(m.max_rss_kb, kBoundedKb);
}

TEST(TraceBombs, ANativeFrameLongerThanAMebibyteIsRefusedAndTheWriterWillNotWriteOne) {
  TempDir dir;
  std::string bytes;
  for (std::size_t i = 0; i <= kMaxTraceFrameBytes; ++i) bytes += " 00";
  const std::string t = dir.write("long.trace", "l6470emu-trace 1\n0 frame 1.00us" + bytes + "\n");
  const Measured m = run_measured({"decode", t});
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find(t + ":2: a frame of 1048577 bytes or more: " + kFrameLimit), std::string::npos) << m.out;

  NativeTraceWriter w(dir.file("w.trace"));
  const std::vector<std::uint8_t> mosi(kMaxTraceFrameBytes + 1);
  EXPECT_THROW(w.write(test::frame_at(0, 4, mosi, {})), std::runtime_error);
}

TEST(TraceBombs, ASaleaeCaptureHoldingOneHugeFrameIsRefusedAtTheRowThatPassesTheLimitWithinBoundedMemory) {
  // The finding: a 2.8 MB gzipped CSV holding one 20 MB frame took 2.2 GB and ended in
  // std::bad_alloc. Here one frame of 1 MiB + 1 bytes in rows padded to ~150 bytes: 160 MB of
  // text, a few hundred kB on disk.
  TempDir dir;
  const std::string name = "\"SPI " + std::string(100, 'x') + "\"";
  std::string csv = "name,type,start_time,duration,\"mosi\",\"miso\"\n" + name + ",\"enable\",0.1,2e-08,,\n";
  const std::string row = name + ",\"result\",0.100000100,0.000000100,0xD0,0x00\n";
  for (std::size_t i = 0; i <= kMaxTraceFrameBytes; ++i) csv += row;
  csv += name + ",\"disable\",0.2,2e-08,,\n";
  ASSERT_GT(csv.size(), 150'000'000u);
  const std::string gz = dir.file("capture.csv.gz");
  write_gz(gz, csv);
  csv.clear();
  csv.shrink_to_fit();
  const Measured m = run_measured({"replay", gz});
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find("l6470emu replay: " + gz + ":1048579: a frame of 1048577 bytes or more: " + kFrameLimit +
                       " (the frame of line 2)\n"),
            std::string::npos)
      << m.out;
  EXPECT_LT(m.max_rss_kb, kBoundedKb);
}

TEST(TraceBombs, ASaleaeCaptureWithMoreFramesThanAllowedIsRefusedAtTheRowThatPassesTheLimit) {
  TempDir dir;
  std::string csv = "name,type,start_time,duration,\"mosi\",\"miso\"\n";
  for (int i = 0; i < 20; ++i) {
    const std::string t = "0." + std::to_string(100 + i);
    csv += "\"SPI\",\"enable\"," + t + ",2e-08,,\n\"SPI\",\"result\"," + t + "001,1e-06,0x00,0x00\n\"SPI\",\"disable\"," +
           t + "01,2e-08,,\n";
  }
  const std::string path = dir.write("capture.csv", csv);
  const Measured m = run_measured({"decode", "--max-frames", "10", path});
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find(path + ":32: the trace holds more than 10 frames, the limit"), std::string::npos) << m.out;
  EXPECT_EQ(run_measured({"decode", "--max-frames", "20", path}).status, 0);
}

TEST(TraceBombs, AnImportThatRunsOutOfMemoryIsOneLineNamingTheFileNotStdBadAlloc) {
#if defined(L6470EMU_TEST_ASAN)
  GTEST_SKIP() << "a sanitizer build's program cannot run under an address-space limit";
#endif
  // A Saleae export without Enable rows, one frame per byte: 3 million frames in memory take
  // ~200 MB, more than the 160 MB of address space the program is given here.
  TempDir dir;
  std::string csv = "name,type,start_time,duration,\"mosi\",\"miso\"\n";
  csv.reserve(3'000'000 * 40);
  char row[96];
  for (int i = 0; i < 3'000'000; ++i) {
    std::snprintf(row, sizeof row, "\"SPI\",\"result\",%d.%06d,1e-07,0xD0,0x00\n", i / 1'000'000, i % 1'000'000);
    csv += row;
  }
  const std::string gz = dir.file("many.csv.gz");
  write_gz(gz, csv);
  csv.clear();
  csv.shrink_to_fit();
  const Measured m = run_measured({"replay", gz}, 160u << 20);
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find("l6470emu replay: " + gz + ": out of memory while reading it (an imported trace takes about 70 "
                       "bytes a frame plus 3 a byte: a lower --max-frames than 10000000 refuses it sooner)\n"),
            std::string::npos)
      << m.out;
  EXPECT_EQ(m.out.find("bad_alloc"), std::string::npos) << m.out;
}

TEST(TraceBombs, AnUmockdevRecordingWithAHugeFrameOrAnEndlessLineIsRefusedWithinBoundedMemory) {
  TempDir dir;
  // CS kept asserted ("C") over 300 transfers of 4 kB: a frame of 1.2 MB.
  std::string text = "@DEV /dev/spidev0.0 (SPI)\nTW 00\n";
  const std::string hex(8192, '0');
  for (int i = 0; i < 300; ++i) text += "CW " + hex + "\n";
  const std::string path = dir.write("big.ioctl", text);
  Measured m = run_measured({"replay", "--chain", "1", path});
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find(path + ":258: a frame of 1048577 bytes or more: " + kFrameLimit + " (the frame of line 2)"),
            std::string::npos)
      << m.out;
  const std::string gz = dir.file("endless.ioctl.gz");
  write_gz(gz, "@DEV /dev/spidev0.0 (SPI)\nTW " + std::string(100'000'000, '0'));
  m = run_measured({"replay", "--format", "umockdev", gz});
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find(gz + ":2: a line longer than 8388608 bytes"), std::string::npos) << m.out;
  EXPECT_LT(m.max_rss_kb, kBoundedKb);
}

TEST(TraceBombs, AnFtraceCaptureWithAHugeFrameOrAnEndlessLineIsRefusedWithinBoundedMemory) {
  TempDir dir;
  std::string tx;
  for (int i = 0; i < 64; ++i) tx += (i ? "-" : "") + std::string("00");
  std::string text = "# tracer: nop\n p-1 [000] ..... 1.000000: spi_set_cs: spi0.0 activate\n";
  for (int i = 0; i < 16'385; ++i)
    text += " p-1 [000] ..... 1.000001: spi_transfer_stop: spi0.0 00000000deadbeef len=64 tx=[" + tx + "] rx=[" + tx +
            "]\n";
  const std::string path = dir.write("trace.txt", text);
  Measured m = run_measured({"decode", path});
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find(path + ":16387: a frame of 1048640 bytes or more: " + kFrameLimit + " (the frame of line 2)"),
            std::string::npos)
      << m.out;
  const std::string gz = dir.file("endless.txt.gz");
  write_gz(gz, "# tracer: nop\n p-1 [000] ..... 1.000000: spi_transfer_stop: spi0.0 00000000deadbeef len=1 tx=[00] "
               "rx=[00]\n p-1 [000] ..... 1.000000: spi_set_cs: spi0.0 activate " + std::string(100'000'000, ' '));
  m = run_measured({"decode", "--format", "ftrace", gz});
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find(gz + ":3: a line longer than 8388608 bytes"), std::string::npos) << m.out;
  EXPECT_LT(m.max_rss_kb, kBoundedKb);
}

TEST(TraceBombs, ASigrokTraceWithAHugeFrameOrAnEndlessStringIsRefusedWithinBoundedMemory) {
  TempDir dir;
  std::string bytes;
  for (std::size_t i = 0; i <= kMaxTraceFrameBytes; ++i) bytes += i ? " D0" : "D0";
  const std::string doc = "{\"traceEvents\": [\n{\"ph\": \"B\", \"ts\": 1, \"pid\": \"spi-1\", \"tid\": \"MOSI transfer\", "
                          "\"name\": \"" + bytes + "\"}\n]}\n";
  const std::string path = dir.write("spi.json", doc);
  Measured m = run_measured({"replay", "--chain", "1", path});
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find(path + ":2: a frame of 1048577 bytes or more: " + kFrameLimit), std::string::npos) << m.out;
  const std::string gz = dir.file("endless.json.gz");
  write_gz(gz, "{\"traceEvents\": [\n{\"ph\": \"B\", \"name\": \"" + std::string(100'000'000, 'D'));
  m = run_measured({"replay", "--format", "sigrok", gz});
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find(gz + ":2: more than 4194304 bytes without a complete JSON token"), std::string::npos) << m.out;
  EXPECT_LT(m.max_rss_kb, kBoundedKb);
}

TEST(TraceBombs, ALogicCaptureDecodedBySigrokCliTakesTheSameFrameLimitNamingTheCapture) {
  if (!test::have_program("sigrok-cli")) GTEST_SKIP() << "sigrok-cli not installed (Debian package sigrok-cli)";
  const std::string vcd = fixture_path("two_chips.vcd");  // 17 frames
  const Measured m = run_measured({"replay", "--max-frames", "5", vcd});
  EXPECT_EQ(m.status, 2) << m.out;
  EXPECT_NE(m.out.find("l6470emu replay: " + vcd + ":"), std::string::npos) << m.out;
  EXPECT_NE(m.out.find(": the trace holds more than 5 frames, the limit"), std::string::npos) << m.out;
}

}  // namespace
}  // namespace l6470emu
