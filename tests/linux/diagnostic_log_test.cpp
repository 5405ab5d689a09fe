// The diagnostic log when its file refuses writes (/dev/full, a FIFO whose reader went away):
// said once on stderr with the file and the reason, every line then on stderr, never a lost line
// or a SIGPIPE. In this process (DiagnosticLog) and in a real program under the preload.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "linux/log.hpp"
#include "run_program.hpp"

namespace l6470emu::test {
namespace {

// Everything written to stderr (fd 2) while it lives.
class StderrCapture {
 public:
  StderrCapture() : file_(std::tmpfile()), saved_(dup(2)) {
    std::fflush(stderr);
    dup2(fileno(file_), 2);
  }
  ~StderrCapture() {
    restore();
    std::fclose(file_);
  }
  std::string text() {
    restore();
    std::string out;
    std::rewind(file_);
    for (int c; (c = std::fgetc(file_)) != EOF;) out += static_cast<char>(c);
    return out;
  }

 private:
  void restore() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    dup2(saved_, 2);
    close(saved_);
    saved_ = -1;
  }
  FILE* file_;
  int saved_;
};

TEST(DiagnosticLogWrites, AFullDeviceIsReportedOnceWithItsReasonAndEveryLineGoesToStderr) {
  // /dev/full under a name of this run's own: the report is once per process and file name, so
  // the test holds when repeated in one process (--gtest_repeat).
  char dir[] = "/tmp/l6470emu-log-XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string full = std::string(dir) + "/full";
  ASSERT_EQ(symlink("/dev/full", full.c_str()), 0);
  StderrCapture capture;
  {
    DiagnosticLog first(full);
    DiagnosticLog second(full);  // the preload has two logs on one file: still one report
    EXPECT_EQ(first.open_error(), 0);
    first.line("first");
    EXPECT_EQ(first.write_error(), ENOSPC);
    first.line("second");
    second.line("third");
  }
  unlink(full.c_str());
  rmdir(dir);
  EXPECT_EQ(capture.text(), "l6470emu: log file '" + full +
                                "' cannot be written (No space left on device): diagnostics go to stderr from "
                                "now on\n"
                                "l6470emu: first\n"
                                "l6470emu: second\n"
                                "l6470emu: third\n");
}

TEST(DiagnosticLogWrites, AFifoWhoseReaderWentAwayIsAnErrorNotASigpipe) {
  char dir[] = "/tmp/l6470emu-log-XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string fifo = std::string(dir) + "/log.fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  const int reader = open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(reader, 0);
  StderrCapture capture;
  {
    DiagnosticLog log(fifo);
    ASSERT_EQ(log.open_error(), 0);
    log.line("heard by the reader");
    close(reader);
    log.line("after the reader left");  // SIGPIPE's default action would end this test program
    EXPECT_EQ(log.write_error(), EPIPE);
  }
  unlink(fifo.c_str());
  rmdir(dir);
  EXPECT_EQ(capture.text(), "l6470emu: log file '" + fifo +
                                "' cannot be written (a FIFO or socket whose reader went away): diagnostics go to "
                                "stderr from now on\n"
                                "l6470emu: after the reader left\n");
}

TEST(DiagnosticLogWrites, AProgramLoggingToDevFullGetsItsDiagnosticsOnStderrAfterOneLineSayingWhy) {
  const std::string why = missing_prerequisites();
  if (!why.empty()) GTEST_SKIP() << why;
  // SPI mode 0 is served as the wire gives it and logged (the chip wants mode 3), once per
  // setting: the answer's first byte has the stale latch (the MSB of 0xD0) as its top bit.
  const RunResult r = run_program({system_python(), "-c",
                                   "import spidev\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 0\n"
                                   "print([hex(s.xfer2([b])[0]) for b in (0xD0, 0, 0)])\n"},
                                  {{"LD_PRELOAD", preload_library()},
                                   {"L6470EMU_CHAIN", "bus=0 cs=0 chips=L6470"},
                                   {"L6470EMU_LOG", "/dev/full"}});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("['0x0', '0xfc', '0x3']"), std::string::npos) << r.out;
  const std::string first =
      "l6470emu: log file '/dev/full' cannot be written (No space left on device): diagnostics go to stderr from now on\n";
  EXPECT_EQ(r.err.rfind(first, 0), 0u) << r.err;
  EXPECT_NE(r.err.find("mode 0"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(first, 1), std::string::npos) << "said once:\n" << r.err;
}

}  // namespace
}  // namespace l6470emu::test
