// `l6470emu serve` under abuse: its socket is the daemon user's alone, it never deletes what is
// not its own stale socket, it stays calm out of descriptors and past its client cap, and ctl
// says exactly what is wrong. (The fuzz harness covers the packet decoder itself.)
#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <thread>

#include <filesystem>
#include <gtest/gtest.h>

#include "linux/packet_memfd.hpp"
#include "linux/protocol.hpp"
#include "raw_client.hpp"
#include "run_program.hpp"
#include "support/test_support.hpp"

namespace l6470emu::test {
namespace {

constexpr const char* kChain = "bus=0 cs=0 chips=L6470";

int connect_to(const std::string& path) { return connect_raw(path); }

/// Whether the daemon answers a hello on `fd` (false: it refused, closed the connection or never answers).
bool answers_hello(int fd) { return say_hello(fd).answered; }

/// Whether the daemon at `path` answers a new client's hello within about 5 s.
bool served_within_5s(const std::string& path) {
  for (int i = 0; i < 50; ++i) {
    const int fd = connect_to(path);
    const bool served = fd >= 0 && answers_hello(fd);
    if (fd >= 0) close(fd);
    if (served) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
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
  // ... refuses it, and tells it why.
  EXPECT_EQ(as_nobody([&] {
              const int fd = connect_to(path);
              if (fd < 0) return 2;
              const HelloOutcome o = say_hello(fd);
              if (o.answered) return 1;
              return o.refusal && o.refusal->find("serves only user 0 and root, not user 65534") != std::string::npos ? 0 : 3;
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
  const bool served = served_within_5s(path);
  EXPECT_TRUE(served) << "the daemon serves again once descriptors are free";
  const RunResult r = d.stop(SIGTERM);
  EXPECT_NE(r.err.find("out of file descriptors"), std::string::npos) << r.err;
}

/// Open descriptors of process `pid`.
std::size_t open_descriptors(pid_t pid) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator("/proc/" + std::to_string(pid) + "/fd")) ++n;
  return n;
}

TEST_F(DaemonLimits, DescriptorsAClientSendsWithAPacketAreNeverKeptOpen) {
  ServeDaemon d(kChain);
  ASSERT_TRUE(d.ready()) << d.process().out();
  const int spare = open("/dev/null", O_RDONLY | O_CLOEXEC);
  ASSERT_GE(spare, 0);
  auto hello_with_two_descriptors = [&] {
    const int fd = connect_to(d.socket());
    if (fd < 0) return false;
    const RequestHeader req{static_cast<std::uint32_t>(Op::hello), 0, 0, kProtocolVersion};
    iovec iov{const_cast<RequestHeader*>(&req), sizeof req};
    alignas(cmsghdr) char control[CMSG_SPACE(2 * sizeof(int))] = {};
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control;
    msg.msg_controllen = sizeof control;
    cmsghdr* c = CMSG_FIRSTHDR(&msg);
    c->cmsg_level = SOL_SOCKET;
    c->cmsg_type = SCM_RIGHTS;
    c->cmsg_len = CMSG_LEN(2 * sizeof(int));
    const int two[2] = {spare, spare};
    std::memcpy(CMSG_DATA(c), two, sizeof two);
    const bool sent = sendmsg(fd, &msg, MSG_NOSIGNAL) == static_cast<ssize_t>(sizeof req);
    char buf[256];
    timeval tv{5, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    (void)recv(fd, buf, sizeof buf, 0);  // the answer (or the hang-up): the daemon has read the packet
    close(fd);
    return sent;
  };
  ASSERT_TRUE(hello_with_two_descriptors());
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const std::size_t before = open_descriptors(d.process().pid());
  for (int i = 0; i < 50; ++i) ASSERT_TRUE(hello_with_two_descriptors());
  // Finished connections are reaped at the daemon's next look (its accept loop wakes each second).
  std::size_t after = open_descriptors(d.process().pid());
  for (int i = 0; i < 40 && after > before + 2; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    after = open_descriptors(d.process().pid());
  }
  EXPECT_LE(after, before + 2) << "50 packets of two descriptors each";
  close(spare);
}

TEST_F(DaemonLimits, ForgedBigPacketEnvelopesAreRefusedWithoutAnyDescriptorKept) {
  ServeDaemon d(kChain);
  ASSERT_TRUE(d.ready()) << d.process().out();
  const RequestHeader hello{static_cast<std::uint32_t>(Op::hello), 0, 0, kProtocolVersion};
  // A memfd holding a hello of `size` bytes (the header, then zeros), sealed or not.
  auto memfd = [&](std::size_t size, bool seal) {
    const int fd = memfd_create("forged", MFD_CLOEXEC | MFD_ALLOW_SEALING);
    if (fd < 0 || ftruncate(fd, static_cast<off_t>(size)) != 0) return -1;
    (void)pwrite(fd, &hello, std::min(size, sizeof hello), 0);
    if (seal) (void)fcntl(fd, F_ADD_SEALS, F_SEAL_WRITE | F_SEAL_GROW | F_SEAL_SHRINK);
    return fd;
  };
  // Sends an envelope saying `size` with `fds` (closed after) and, when `wait`, waits for the
  // hang-up (the daemon reaps a finished connection within a second). Whether the daemon
  // answered with a packet (it must not).
  bool wait = true;
  bool refused = false;
  auto forged = [&](std::uint64_t size, std::vector<int> fds) {
    const int fd = connect_to(d.socket());
    if (fd < 0) return true;
    BigPacketEnvelope e;
    e.size = size;
    iovec iov{&e, sizeof e};
    alignas(cmsghdr) char control[CMSG_SPACE(2 * sizeof(int))] = {};
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    if (!fds.empty()) {
      msg.msg_control = control;
      msg.msg_controllen = CMSG_SPACE(fds.size() * sizeof(int));
      cmsghdr* c = CMSG_FIRSTHDR(&msg);
      c->cmsg_level = SOL_SOCKET;
      c->cmsg_type = SCM_RIGHTS;
      c->cmsg_len = CMSG_LEN(fds.size() * sizeof(int));
      std::memcpy(CMSG_DATA(c), fds.data(), fds.size() * sizeof(int));
    }
    (void)sendmsg(fd, &msg, MSG_NOSIGNAL);
    for (int f : fds) close(f);
    if (!wait) {  // the packet stays queued for the daemon after we close
      close(fd);
      return false;
    }
    char buf[256];
    timeval tv{5, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    const ssize_t n = recv(fd, buf, sizeof buf, 0);
    close(fd);
    // A refusal (this process still has kMaxClientsPerProcess connections the daemon has not
    // finished with, on a slow machine after the flood below) is not an answer to the envelope.
    refused = n > 0 && decode_refusal({reinterpret_cast<const std::uint8_t*>(buf), static_cast<std::size_t>(n)});
    return n > 0 && !refused;
  };
  auto all_forgeries = [&] {
    int pipe_fds[2];
    if (pipe2(pipe_fds, O_CLOEXEC) != 0) return true;
    bool answered = forged(200000, {});                                   // no memfd
    answered |= forged(200000, {memfd(100000, true)});                    // another size
    answered |= forged(kMaxPacket + 1, {memfd(kMaxPacket + 1, true)});    // larger than a packet
    answered |= forged(200000, {memfd(200000, false)});                   // not sealed
    answered |= forged(200000, {pipe_fds[0], pipe_fds[1]});               // not a memfd
    answered |= forged(200000, {memfd(100000, true), memfd(10, true)});   // wrong, with a second
    return answered;
  };
  EXPECT_FALSE(all_forgeries());
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const std::size_t before = open_descriptors(d.process().pid());
  wait = false;
  for (int i = 0; i < 10; ++i) all_forgeries();
  wait = true;
  // The daemon reads them all, and then this one too: until it has finished with the flood's
  // connections, this process may be at its limit of connections and refused.
  bool answered = forged(200000, {memfd(100000, true), memfd(10, true)});
  for (int i = 0; i < 100 && refused; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    answered = forged(200000, {memfd(100000, true), memfd(10, true)});
  }
  EXPECT_FALSE(refused) << "still refused after 10 s";
  EXPECT_FALSE(answered);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));          // and reaped their connections
  std::size_t after = open_descriptors(d.process().pid());
  for (int i = 0; i < 40 && after > before + 2; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    after = open_descriptors(d.process().pid());
  }
  EXPECT_LE(after, before + 2) << "61 forged envelopes";
  // A well-formed big packet (a hello padded past the inline limit is refused by its size, but
  // answered) and an ordinary client are still served.
  const int fd = connect_to(d.socket());
  ASSERT_GE(fd, 0);
  const std::vector<std::uint8_t> padding(kInlinePacket + 1);
  ASSERT_TRUE(send_packet(fd, &hello, sizeof hello, padding, -1));
  Packet reply;
  int passed = -1;
  ASSERT_TRUE(recv_packet(fd, reply, passed, true));
  EXPECT_EQ(passed, -1);
  ReplyHeader rep;
  ASSERT_GE(reply.size, sizeof rep);
  std::memcpy(&rep, reply.data.get(), sizeof rep);
  EXPECT_EQ(rep.result, -EPROTO) << "the header says no payload, the packet has one";
  close(fd);
  EXPECT_TRUE(served_within_5s(d.socket()));
}

TEST_F(DaemonLimits, OutOfMemoryForAClientRefusesItAndTheDaemonServesOn) {
#if defined(L6470EMU_TEST_ASAN)
  GTEST_SKIP() << "an AddressSanitizer build cannot start under ulimit -v";
#endif
  // Under ulimit -v, client threads get their stacks but not always their buffers: each such
  // client is refused with the reason (std::bad_alloc escaped the thread and aborted the daemon).
  const std::string path = temp_socket_path("enomem");
  Background d({"/bin/sh", "-c", "ulimit -v 300000; exec \"$0\" serve --chain \"$1\" --socket \"$2\"",
                l6470emu_program(), kChain, path});
  for (int i = 0; i < 500 && d.out().find("listening on") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::vector<int> clients;
  for (int i = 0; i < 40; ++i)
    if (const int fd = connect_to(path); fd >= 0) {
      (void)say_hello(fd);
      clients.push_back(fd);
    }
  EXPECT_EQ(kill(d.pid(), 0), 0) << "the daemon is alive";
  for (int fd : clients) close(fd);
  const bool served = served_within_5s(path);
  EXPECT_TRUE(served) << "clients are served once the others left";
  const RunResult r = d.stop(SIGTERM);
  EXPECT_EQ(r.status, 0) << r.err;
}

TEST_F(DaemonLimits, ClientsPastTheCapAreRefusedToldWhyAndTheRestServed) {
  ServeDaemon d(kChain);
  ASSERT_TRUE(d.ready());
  // 16 processes of 16 connections fill the 256 slots; the 17th process is refused, and told why.
  std::vector<std::unique_ptr<ConnectionHolder>> holders;
  int answered = 0;
  for (int i = 0; i < 16; ++i) {
    holders.push_back(std::make_unique<ConnectionHolder>(d.socket(), 16));
    answered += holders.back()->answered();
  }
  EXPECT_EQ(answered, 256);
  {
    ConnectionHolder late(d.socket(), 4);
    EXPECT_EQ(late.answered(), 0);
    EXPECT_EQ(late.refused(), 4);
    EXPECT_NE(late.first_refusal().find("already serves 256 clients, the most it serves at once"), std::string::npos)
        << late.first_refusal();
  }
  // ctl and a preload program refused at the cap say so, not "did not answer".
  const RunResult refused = d.ctl({"status"});
  EXPECT_EQ(refused.status, 1);
  EXPECT_NE(refused.err.find("refused the connection: the daemon at " + d.socket() + " already serves 256 clients"),
            std::string::npos)
      << refused.err;
  const RunResult program = run_program({system_python(), "-c", "import os; print(os.path.exists('/dev/spidev0.0'))"}, d.env());
  EXPECT_EQ(program.out, "False\n");
  EXPECT_NE(program.err.find("refused this program: the daemon at " + d.socket() + " already serves 256 clients"),
            std::string::npos)
      << program.err;
  holders.clear();
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the accept loop reaps at least once a second
  const RunResult t = d.ctl({"time"});
  EXPECT_EQ(t.status, 0) << t.err;
  const RunResult r = d.process().stop(SIGTERM);
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.err.find("256 clients connected; refusing more"), std::string::npos) << r.err;
}

TEST_F(DaemonLimits, OneProcessCannotTakeEverySlot) {
  ServeDaemon d(kChain);
  ASSERT_TRUE(d.ready());
  ConnectionHolder greedy(d.socket(), 20);
  EXPECT_EQ(greedy.answered(), 16);
  EXPECT_EQ(greedy.refused(), 4);
  EXPECT_NE(greedy.first_refusal().find("process " + std::to_string(greedy.pid()) +
                                        " already has 16 connections to the daemon at " + d.socket() +
                                        ", the most one process may have (16)"),
            std::string::npos)
      << greedy.first_refusal();
  // Every other process is still served.
  ConnectionHolder other(d.socket(), 2);
  EXPECT_EQ(other.answered(), 2);
  const RunResult c = d.ctl({"clients"});
  EXPECT_EQ(c.status, 0) << c.err;
  EXPECT_EQ(c.out.rfind("19 clients\n", 0), 0u) << c.out;  // 16 + 2 + ctl itself
  EXPECT_NE(d.process().stop(SIGTERM).err.find("process " + std::to_string(greedy.pid()) + " has 16 connections"),
            std::string::npos);
}

TEST_F(DaemonLimits, CtlSaysWhichChipDoesNotExist) {
  ServeDaemon d(kChain);
  ASSERT_TRUE(d.ready());
  for (const char* k : {"3", "99999", "99999999999999999999", "000000000000000000000000000000000000001"}) {
    const RunResult r = d.ctl({"get", "ABS_POS", "--chip", k});
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(r.err, std::string("ctl: chip ") + k + " does not exist (the chain has 1)\n");
  }
  const RunResult r = d.ctl({"get", "ABS_POS", "--chip", "-1"});
  EXPECT_EQ(r.err, "ctl: --chip needs a chip number, not '-1'\n");
  EXPECT_EQ(d.ctl({"get", "ABS_POS", "--chip", "0"}).out, "chip 0: ABS_POS = 0x000000 (0)\n");
}

TEST_F(DaemonLimits, CtlAdvanceTakesOnlyExactBoundedMilliseconds) {
  ServeDaemon d(kChain, {"--virtual-time"});
  ASSERT_TRUE(d.ready());
  // Each refused with one line and status 2; the daemon (UBSan-built too) carries on.
  for (const char* bad : {"inf", "1e308", "4e15", "nan", "-1", "1e3", "0x10", "1.", ".5", "1.5.2", "1.0000000001",
                          "10000000000.5", "10000000001", "99999999999999999999999"}) {
    const RunResult r = d.ctl({"advance", bad});
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_EQ(r.err.rfind(std::string("ctl: advance: '") + bad + "' is ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
  EXPECT_NE(d.ctl({"time"}).out.find(": 0 ticks"), std::string::npos);
  const RunResult ok = d.ctl({"advance", "1.5"});
  EXPECT_EQ(ok.out, "advanced 1.5 ms (6000 ticks)\n") << ok.err;
  EXPECT_EQ(d.ctl({"advance", "0.00025"}).out, "advanced 0.00025 ms (1 tick)\n");
  EXPECT_NE(d.ctl({"time"}).out.find(": 6001 ticks"), std::string::npos);
  EXPECT_EQ(d.ctl({"advance", "10000000000"}).out, "advanced 10000000000 ms (40000000000000 ticks)\n");
  EXPECT_NE(d.ctl({"time"}).out.find(": 40000000006001 ticks"), std::string::npos) << d.ctl({"time"}).out;
  EXPECT_EQ(d.process().stop(SIGTERM).status, 0);
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

TEST(DaemonProtocol, AMessageOfMoreTransfersThanSpidevTakesIsRefusedAsTheKernelWould) {
  // 512 transfers of 1 byte with the longest delay each: 33 s of bus time at 511, refused at 512
  // (a raw client's packet; no SPI_IOC_MESSAGE can carry more than 511).
  ParseResult p = parse_board_config(kChain, "test");
  ASSERT_TRUE(p.config);
  DiagnosticLog log("off");
  DeviceBoard board(*p.config, log);
  const NewFile f = board.open(0, true);
  for (const std::size_t n : {std::size_t{512}, std::size_t{4096}}) {
    const std::size_t payload = n * sizeof(spi_ioc_transfer) + n;  // the transfers, then their tx bytes
    RequestHeader req{static_cast<std::uint32_t>(Op::spi_message), static_cast<std::uint32_t>(payload), f.handle, n};
    std::vector<std::uint8_t> packet(sizeof req + payload);
    std::memcpy(packet.data(), &req, sizeof req);
    for (std::size_t i = 0; i < n; ++i) {
      spi_ioc_transfer t{};
      t.tx_buf = 1;
      t.len = 1;
      t.delay_usecs = 65535;
      std::memcpy(packet.data() + sizeof req + i * sizeof t, &t, sizeof t);
    }
    ReplyHeader reply;
    std::vector<std::uint8_t> out;
    int pass_fd = -1;
    serve_request(board, {}, packet, reply, out, pass_fd);
    EXPECT_EQ(reply.result, -EINVAL) << n << " transfers";
  }
  close(f.fd);
}

}  // namespace
}  // namespace l6470emu::test
