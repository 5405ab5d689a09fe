// `l6470emu serve` under abuse: its socket is the daemon user's alone, it never deletes what is
// not its own stale socket, it stays calm out of descriptors and past its client cap, and ctl
// says exactly what is wrong. (The fuzz harness covers the packet decoder itself.)
#include <fcntl.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "linux/protocol.hpp"
#include "run_program.hpp"

namespace l6470emu::test {
namespace {

constexpr const char* kChain = "bus=0 cs=0 chips=L6470";

int connect_to(const std::string& path) {
  const int s = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  std::strncpy(a.sun_path, path.c_str(), sizeof a.sun_path - 1);
  if (connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    close(s);
    return -1;
  }
  return s;
}

/// Whether the daemon answers a hello on `fd` (false: it closed the connection or never answers).
bool answers_hello(int fd) {
  const RequestHeader req{static_cast<std::uint32_t>(Op::hello), 0, 0, kProtocolVersion};
  if (send(fd, &req, sizeof req, MSG_NOSIGNAL) != static_cast<ssize_t>(sizeof req)) return false;
  timeval tv{5, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  std::uint8_t buf[4096];
  return recv(fd, buf, sizeof buf, 0) >= static_cast<ssize_t>(sizeof(ReplyHeader));
}

/// User and system CPU seconds a process has used so far.
double cpu_seconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string s((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::istringstream rest(s.substr(s.rfind(')') + 2));
  std::string field;
  double utime = 0, stime = 0;
  for (int i = 3; i <= 15 && rest >> field; ++i) {
    if (i == 14) utime = std::stod(field);
    if (i == 15) stime = std::stod(field);
  }
  return (utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

/// Runs `f` in a child process as user nobody (65534); returns its exit status.
template <typename F>
int as_nobody(F f) {
  const pid_t pid = fork();
  if (pid == 0) {
    if (setgid(65534) != 0 || setuid(65534) != 0) _exit(99);
    _exit(f());
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

class DaemonLimits : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
  }
};

TEST_F(DaemonLimits, ServeRefusesToDeleteARegularFileAtItsSocketPath) {
  const std::string path = temp_socket_path("not-a-socket");
  { std::ofstream(path) << "precious\n"; }
  const RunResult r = run_program({l6470emu_program(), "serve", "--chain", kChain, "--socket", path}, {}, 10);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("exists and is not a socket"), std::string::npos) << r.err;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "precious");
  unlink(path.c_str());
}

TEST_F(DaemonLimits, TheSocketIsOwnerOnlyWhateverTheUmask) {
  const std::string path = temp_socket_path("umask");
  Background d({"/bin/sh", "-c", "umask 000; exec \"$0\" serve --chain \"$1\" --socket \"$2\"", l6470emu_program(), kChain,
                path});
  for (int i = 0; i < 500 && d.out().find("listening on") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  struct stat st{};
  ASSERT_EQ(stat(path.c_str(), &st), 0) << d.out();
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_EQ(d.stop(SIGTERM).status, 0);
}

TEST_F(DaemonLimits, AClientOfAnotherUserIsRefusedEvenWhenTheSocketModeWouldLetItIn) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to run a client as another user";
  ServeDaemon d(kChain);
  ASSERT_TRUE(d.ready());
  const std::string path = d.socket();
  // Owner-only socket: another user cannot even connect.
  EXPECT_EQ(as_nobody([&] { return connect_to(path) < 0 ? 0 : 1; }), 0);
  // A socket opened up by hand (chmod 666, a wider directory): the daemon checks the peer itself.
  ASSERT_EQ(chmod(path.c_str(), 0666), 0);
  // The socket's directory must be reachable for nobody too.
  const std::string dir = path.substr(0, path.rfind('/'));
  struct stat dst{};
  stat(dir.c_str(), &dst);
  chmod(dir.c_str(), dst.st_mode | 0011);
  EXPECT_EQ(as_nobody([&] {
              const int fd = connect_to(path);
              if (fd < 0) return 2;
              return answers_hello(fd) ? 1 : 0;
            }),
            0);
  chmod(dir.c_str(), dst.st_mode);
  const int mine = connect_to(path);
  EXPECT_TRUE(answers_hello(mine));  // and it goes on serving its own user
  close(mine);
  const RunResult r = d.process().stop(SIGTERM);
  EXPECT_NE(r.err.find("refused a client of user 65534"), std::string::npos) << r.err;
}

TEST_F(DaemonLimits, ASocketPathAnotherUserClaimedFirstIsRefused) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to create a socket as another user";
  const std::string path = "/tmp/l6470emu-test-claimed-" + std::to_string(getpid()) + ".sock";
  unlink(path.c_str());
  ASSERT_EQ(as_nobody([&] {
              const int s = socket(AF_UNIX, SOCK_SEQPACKET, 0);
              sockaddr_un a{};
              a.sun_family = AF_UNIX;
              std::strncpy(a.sun_path, path.c_str(), sizeof a.sun_path - 1);
              return bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 ? 0 : 1;
            }),
            0);
  const RunResult r = run_program({l6470emu_program(), "serve", "--chain", kChain, "--socket", path}, {}, 10);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("belongs to user 65534"), std::string::npos) << r.err;
  unlink(path.c_str());
}

TEST_F(DaemonLimits, OutOfDescriptorsTheDaemonWaitsInsteadOfSpinningAndRecovers) {
  const std::string path = temp_socket_path("emfile");
  Background d({"/bin/sh", "-c", "ulimit -n 24; exec \"$0\" serve --chain \"$1\" --socket \"$2\"", l6470emu_program(),
                kChain, path});
  for (int i = 0; i < 500 && d.out().find("listening on") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::vector<int> clients;
  for (int i = 0; i < 40; ++i)
    if (const int fd = connect_to(path); fd >= 0) clients.push_back(fd);  // the backlog accepts them all
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const double before = cpu_seconds(d.pid());
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const double used = cpu_seconds(d.pid()) - before;
  EXPECT_LT(used, 0.3) << "a spinning accept loop burns a whole core";
  for (int fd : clients) close(fd);
  bool served = false;
  for (int i = 0; i < 50 && !served; ++i) {
    const int fd = connect_to(path);
    served = fd >= 0 && answers_hello(fd);
    if (fd >= 0) close(fd);
    if (!served) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_TRUE(served) << "the daemon serves again once descriptors are free";
  const RunResult r = d.stop(SIGTERM);
  EXPECT_NE(r.err.find("out of file descriptors"), std::string::npos) << r.err;
}

TEST_F(DaemonLimits, ClientsPastTheCapAreRefusedAndTheRestServed) {
  ServeDaemon d(kChain);
  ASSERT_TRUE(d.ready());
  std::vector<int> clients;
  for (int i = 0; i < 300; ++i)
    if (const int fd = connect_to(d.socket()); fd >= 0) clients.push_back(fd);
  ASSERT_EQ(clients.size(), 300u);
  int answered = 0;
  for (int fd : clients) answered += answers_hello(fd) ? 1 : 0;
  EXPECT_EQ(answered, 256);
  for (int fd : clients) close(fd);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the accept loop reaps at least once a second
  const RunResult t = d.ctl({"time"});
  EXPECT_EQ(t.status, 0) << t.err;
  const RunResult r = d.process().stop(SIGTERM);
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.err.find("256 clients connected; refusing more"), std::string::npos) << r.err;
}

TEST_F(DaemonLimits, CtlSaysWhichChipDoesNotExist) {
  ServeDaemon d(kChain);
  ASSERT_TRUE(d.ready());
  for (const char* k : {"3", "99999"}) {
    const RunResult r = d.ctl({"get", "ABS_POS", "--chip", k});
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err, std::string("ctl: chip ") + k + " does not exist (the chain has 1)\n");
  }
  const RunResult r = d.ctl({"get", "ABS_POS", "--chip", "-1"});
  EXPECT_EQ(r.err, "ctl: --chip needs a chip number, not '-1'\n");
  EXPECT_EQ(d.ctl({"get", "ABS_POS", "--chip", "0"}).out, "chip 0: ABS_POS = 0x000000 (0)\n");
}

TEST_F(DaemonLimits, CtlTraceStartDoesNotEndARecordingInProgress) {
  const std::string trace = temp_socket_path("rec") + ".trace";
  ServeDaemon d(kChain, {"--record", trace});
  ASSERT_TRUE(d.ready());
  const RunResult r = d.ctl({"trace", "start", trace + ".other"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("is already being recorded to " + trace), std::string::npos) << r.err;
  EXPECT_EQ(access((trace + ".other").c_str(), F_OK), -1);
  EXPECT_NE(d.process().stop(SIGTERM).out.find("recorded"), std::string::npos);
  unlink(trace.c_str());
}

TEST(DaemonProtocol, AnEmptySpiMessageIsAnsweredWithoutTouchingTheBus) {
  ParseResult p = parse_board_config(kChain, "test");
  ASSERT_TRUE(p.config);
  DiagnosticLog log("off");
  DeviceBoard board(*p.config, log);
  const NewFile f = board.open(0, true);
  RequestHeader req{static_cast<std::uint32_t>(Op::spi_message), 0, f.handle, 0};
  std::vector<std::uint8_t> packet(sizeof req);
  std::memcpy(packet.data(), &req, sizeof req);
  ReplyHeader reply;
  std::vector<std::uint8_t> out;
  int pass_fd = -1;
  serve_request(board, {}, packet, reply, out, pass_fd);
  EXPECT_EQ(reply.result, 0);
  EXPECT_TRUE(out.empty());
  close(f.fd);
}

}  // namespace
}  // namespace l6470emu::test
