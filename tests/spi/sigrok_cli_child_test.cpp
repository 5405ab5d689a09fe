// sigrok-cli as the child that decodes VCD and .sr captures (tools/trace_input.cpp): it is
// stopped after its time limit (a malformed VCD header can make it run for ever) and it dies
// with the process that started it (a SIGKILLed l6470emu must not leave it running). A shell
// script stands in for sigrok-cli.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "support/trace_test_support.hpp"
#include "tools/trace_input.hpp"

namespace l6470emu {
namespace {

using test::TempDir;
using Clock = std::chrono::steady_clock;

/// A fake sigrok-cli that writes its pid to `pid_file` and then sleeps for a minute.
std::string hanging_sigrok_cli(const TempDir& dir, const std::string& pid_file) {
  const std::string path = dir.write("sigrok-cli", "#!/bin/sh\necho $$ > '" + pid_file + "'\nexec sleep 60\n");
  chmod(path.c_str(), 0755);
  return path;
}

/// The pid written to `pid_file`, waiting up to 10 s for it; 0 if none.
pid_t wait_for_pid(const std::string& pid_file) {
  for (auto until = Clock::now() + std::chrono::seconds(10); Clock::now() < until;) {
    pid_t pid = 0;
    if (std::ifstream(pid_file) >> pid && pid > 0) return pid;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return 0;
}

/// Whether `pid` is a live process (a zombie nobody reaped counts as gone).
bool alive(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  if (!std::getline(stat, text)) return false;
  const std::size_t close = text.rfind(')');
  return close != std::string::npos && close + 2 < text.size() && text[close + 2] != 'Z' && text[close + 2] != 'X';
}

TEST(SigrokCliChild, IsStoppedWhenItOutlivesItsTimeLimit) {
  TempDir dir;
  const std::string pid_file = dir.file("pid");
  TraceInputOptions options;
  options.sigrok_cli = hanging_sigrok_cli(dir, pid_file);
  options.sigrok_time_limit = std::chrono::seconds(1);
  const auto start = Clock::now();
  try {
    run_sigrok_spi_decoder(dir.write("capture.vcd", "$timescale 10ns $end\n#-1e308\n"), options);
    ADD_FAILURE() << "no error";
  } catch (const TraceError& e) {
    EXPECT_NE(std::string(e.what()).find("sigrok-cli did not finish within 1 s and was stopped"), std::string::npos)
        << e.what();
  }
  EXPECT_LT(Clock::now() - start, std::chrono::seconds(10));
  const pid_t pid = wait_for_pid(pid_file);
  ASSERT_GT(pid, 0);
  EXPECT_FALSE(alive(pid));
}

TEST(SigrokCliChild, DiesWithTheProcessThatStartedIt) {
  TempDir dir;
  const std::string pid_file = dir.file("pid");
  TraceInputOptions options;
  options.sigrok_cli = hanging_sigrok_cli(dir, pid_file);
  options.sigrok_time_limit = std::chrono::seconds(60);
  const std::string capture = dir.write("capture.vcd", "$timescale 10ns $end\n");
  const pid_t emulator = fork();
  ASSERT_GE(emulator, 0);
  if (emulator == 0) {
    try {
      run_sigrok_spi_decoder(capture, options);
    } catch (...) {
    }
    _exit(0);
  }
  const pid_t sigrok = wait_for_pid(pid_file);
  kill(emulator, SIGKILL);
  waitpid(emulator, nullptr, 0);
  ASSERT_GT(sigrok, 0);
  bool gone = false;
  for (auto until = Clock::now() + std::chrono::seconds(10); Clock::now() < until && !gone;) {
    gone = !alive(sigrok);
    if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_TRUE(gone) << "sigrok-cli (pid " << sigrok << ") outlived the SIGKILLed process that started it";
  if (!gone) kill(sigrok, SIGKILL);
}

TEST(SigrokCliChild, SaysWhenTheProgramIsMissing) {
  TraceInputOptions options;
  options.sigrok_cli = "/nonexistent/sigrok-cli";
  try {
    run_sigrok_spi_decoder("capture.vcd", options);
    ADD_FAILURE() << "no error";
  } catch (const TraceError& e) {
    EXPECT_STREQ(e.what(), "capture.vcd: cannot run /nonexistent/sigrok-cli (No such file or directory): install the "
                           "sigrok-cli package to read logic captures");
  }
}

}  // namespace
}  // namespace l6470emu
