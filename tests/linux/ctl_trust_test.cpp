// ctl and the preload trust a daemon's socket only as far as they should: a socket served by
// another user is not talked to, and what a server of one's own user says is printed with every
// terminal escape sequence defused and cannot choose ctl's exit status.
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "linux/protocol.hpp"
#include "run_program.hpp"

namespace l6470emu::test {
namespace {

/// A listening socket at `path`, or -1.
int listen_at(const std::string& path) {
  unlink(path.c_str());
  const int s = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  std::strncpy(a.sun_path, path.c_str(), sizeof a.sun_path - 1);
  if (bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 || listen(s, 8) != 0) {
    close(s);
    return -1;
  }
  return s;
}

/// The reply packet a server sends: `result` and `text`.
std::string reply_packet(std::int64_t result, const std::string& text) {
  ReplyHeader h{};
  h.result = result;
  h.payload = static_cast<std::uint32_t>(text.size());
  return std::string(reinterpret_cast<const char*>(&h), sizeof h) + text;
}

/// Answers every connection on `listener` with `reply` (after reading its request) until killed.
[[noreturn]] void answer_forever(int listener, const std::string& reply) {
  for (;;) {
    const int c = accept(listener, nullptr, nullptr);
    if (c < 0) continue;
    char buf[4096];
    (void)!recv(c, buf, sizeof buf, 0);
    (void)!send(c, reply.data(), reply.size(), MSG_NOSIGNAL);
    close(c);
  }
}

/// A hostile server in a child process: as user `uid` (65534: nobody) when given, answering
/// `reply` at `path`. Killed when destroyed.
class FakeServer {
 public:
  FakeServer(const std::string& path, const std::string& reply, uid_t uid = geteuid()) : path_(path) {
    int ready[2];
    if (pipe(ready) != 0) return;
    pid_ = fork();
    if (pid_ == 0) {
      close(ready[0]);
      if (uid != geteuid() && (setgid(uid) != 0 || setuid(uid) != 0)) _exit(99);
      const int l = listen_at(path);
      const char ok = l >= 0 ? 1 : 0;
      (void)!write(ready[1], &ok, 1);
      if (l < 0) _exit(98);
      answer_forever(l, reply);
    }
    close(ready[1]);
    char ok = 0;
    listening_ = read(ready[0], &ok, 1) == 1 && ok == 1;
    close(ready[0]);
  }
  ~FakeServer() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    unlink(path_.c_str());
  }
  bool listening() const { return listening_; }

 private:
  std::string path_;
  pid_t pid_ = -1;
  bool listening_ = false;
};

const std::string kHostileText = "\x1b]0;owned\x07\x1b[2J\x1b[31mred\xc2\x9b" "31m \xff\xfe tab\there\n";

RunResult ctl_at(const std::string& socket, const std::vector<std::string>& words) {
  std::vector<std::string> argv = {l6470emu_program(), "ctl", "--socket", socket};
  argv.insert(argv.end(), words.begin(), words.end());
  return run_program(argv, {}, 10);
}

TEST(CtlTrust, CtlDoesNotTalkToASocketServedByAnotherUser) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to run a server as another user";
  // /tmp is writable by everyone: another user can be there first at the default path.
  const std::string path = "/tmp/l6470emu-test-foreign-" + std::to_string(getpid()) + ".sock";
  FakeServer server(path, reply_packet(77, kHostileText), 65534);
  ASSERT_TRUE(server.listening());
  const RunResult r = ctl_at(path, {"status"});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err.rfind("l6470emu ctl: the socket " + path + " is served by user 65534 (pid ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("), not by you (user 0) or root: not talking to it\n"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.find("owned"), std::string::npos);
}

TEST(CtlTrust, ThePreloadDoesNotUseASocketServedByAnotherUser) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to run a server as another user";
  if (const std::string why = missing_prerequisites(); !why.empty()) GTEST_SKIP() << why;
  const std::string path = "/tmp/l6470emu-test-foreign-preload-" + std::to_string(getpid()) + ".sock";
  FakeServer server(path, reply_packet(0, "spidev /dev/spidev0.0 spidev0.0 153 0 4096\n"), 65534);
  ASSERT_TRUE(server.listening());
  const RunResult r = run_program({system_python(), "-c", "import os; print(os.path.exists('/dev/spidev0.0'))"},
                                  {{"LD_PRELOAD", preload_library()}, {"L6470EMU_SOCKET", path}});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "False\n");
  EXPECT_NE(r.err.find("the socket " + path + " is served by user 65534"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not talking to it; no emulated devices"), std::string::npos) << r.err;
}

TEST(CtlTrust, WhatAServerSaysIsPrintedWithoutEscapeSequencesAndCannotChooseTheExitStatus) {
  const std::string path = temp_socket_path("hostile");
  const std::string escaped = "\\x1B]0;owned\\x07\\x1B[2J\\x1B[31mred\\xC2\\x9B31m \\xFF\\xFE tab\there\n";
  {
    FakeServer server(path, reply_packet(77, kHostileText));
    ASSERT_TRUE(server.listening());
    const RunResult r = ctl_at(path, {"status"});
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err, escaped + "l6470emu ctl: the daemon at " + path +
                         " answered with status 77 (a ctl status is 0, 1 or 2); taken as a failure\n");
  }
  {
    FakeServer server(path, reply_packet(0, kHostileText + "caf\xc3\xa9 \xe2\x86\x92 ok"));
    ASSERT_TRUE(server.listening());
    const RunResult r = ctl_at(path, {"status"});
    EXPECT_EQ(r.status, 0);
    EXPECT_EQ(r.out, escaped + "caf\xc3\xa9 \xe2\x86\x92 ok\n");  // UTF-8 kept, a newline added
  }
  {
    FakeServer server(path, reply_packet(-5, "partial\n"));  // -EIO: the daemon could not do it
    ASSERT_TRUE(server.listening());
    const RunResult r = ctl_at(path, {"status"});
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err, "partial\nl6470emu ctl: the daemon at " + path + " did not carry out the command: " +
                         std::strerror(EIO) + "\n");
  }
  {
    FakeServer server(path, std::string("\x1b[2J", 4));  // shorter than a reply header
    ASSERT_TRUE(server.listening());
    const RunResult r = ctl_at(path, {"status"});
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err, "l6470emu ctl: the daemon at " + path + " sent a reply of 4 bytes, shorter than a reply header\n");
  }
}

}  // namespace
}  // namespace l6470emu::test
