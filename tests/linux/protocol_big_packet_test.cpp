// Packets larger than a socket's buffer between preload, ctl and daemon: send_packet puts one of
// more than kInlinePacket bytes in a sealed memfd, recv_packet reads it back whole, with the
// reply's own descriptor alongside; small packets stay one datagram; a forged envelope (no memfd,
// a memfd of another size, not a memfd, an unsealed one) is refused and leaves no descriptor open.
#include <dirent.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "linux/packet_memfd.hpp"
#include "linux/protocol.hpp"

namespace l6470emu::test {
namespace {

/// Descriptors open in this process.
int open_descriptors() {
  int n = 0;
  if (DIR* d = opendir("/proc/self/fd")) {
    while (readdir(d)) ++n;
    closedir(d);
  }
  return n;
}

std::vector<std::uint8_t> pattern(std::size_t n) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>(i * 131 + (i >> 11));
  return v;
}

class ProtocolBigPackets : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_EQ(socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv_), 0); }
  void TearDown() override {
    close(sv_[0]);
    close(sv_[1]);
  }
  /// Sends `bytes` with `fds` (as many as given) as one raw datagram on the first end.
  void send_raw(const void* bytes, std::size_t n, std::vector<int> fds) {
    iovec iov{const_cast<void*>(bytes), n};
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    alignas(cmsghdr) char control[CMSG_SPACE(4 * sizeof(int))] = {};
    if (!fds.empty()) {
      msg.msg_control = control;
      msg.msg_controllen = CMSG_SPACE(fds.size() * sizeof(int));
      cmsghdr* c = CMSG_FIRSTHDR(&msg);
      c->cmsg_level = SOL_SOCKET;
      c->cmsg_type = SCM_RIGHTS;
      c->cmsg_len = CMSG_LEN(fds.size() * sizeof(int));
      std::memcpy(CMSG_DATA(c), fds.data(), fds.size() * sizeof(int));
    }
    ASSERT_EQ(sendmsg(sv_[0], &msg, MSG_NOSIGNAL), static_cast<ssize_t>(n)) << std::strerror(errno);
  }
  /// Sends an envelope saying `size` with `fds`, closes our copies, and expects recv_packet to
  /// refuse it with EPROTO leaving no descriptor open.
  void expect_refused(std::uint64_t size, std::vector<int> fds, std::uint32_t reserved = 0) {
    BigPacketEnvelope e;
    e.size = size;
    e.reserved = reserved;
    send_raw(&e, sizeof e, fds);
    for (int f : fds) close(f);
    const int before = open_descriptors();
    Packet p;
    int fd = 7777;
    errno = 0;
    EXPECT_FALSE(recv_packet(sv_[1], p, fd, true));
    EXPECT_EQ(errno, EPROTO);
    EXPECT_EQ(fd, -1);
    EXPECT_EQ(open_descriptors(), before) << "every descriptor that came with the envelope is closed";
  }
  int sv_[2] = {-1, -1};
};

int sealed_memfd(std::size_t size, bool seal) {
  const int fd = memfd_create("test", MFD_CLOEXEC | MFD_ALLOW_SEALING);
  if (fd < 0 || ftruncate(fd, static_cast<off_t>(size)) != 0) return -1;
  if (seal && fcntl(fd, F_ADD_SEALS, F_SEAL_WRITE | F_SEAL_GROW | F_SEAL_SHRINK) != 0) return -1;
  return fd;
}

TEST_F(ProtocolBigPackets, AOneMebibyteReplyLargerThanTheSocketBufferArrivesWhole) {
  const std::vector<std::uint8_t> payload = pattern(std::size_t{1} << 20);
  ReplyHeader h{};
  h.result = 3;
  h.payload = static_cast<std::uint32_t>(payload.size());
  const int before = open_descriptors();
  ASSERT_TRUE(send_packet(sv_[0], &h, sizeof h, payload, -1)) << std::strerror(errno);
  Packet p;
  int fd = -1;
  ASSERT_TRUE(recv_packet(sv_[1], p, fd, true)) << std::strerror(errno);
  EXPECT_EQ(fd, -1);
  ASSERT_EQ(p.size, sizeof h + payload.size());
  ReplyHeader got;
  std::memcpy(&got, p.data.get(), sizeof got);
  EXPECT_EQ(got.result, 3);
  EXPECT_EQ(got.payload, payload.size());
  EXPECT_EQ(std::memcmp(p.data.get() + sizeof h, payload.data(), payload.size()), 0);
  EXPECT_EQ(open_descriptors(), before) << "the memfd is closed at both ends";
}

TEST_F(ProtocolBigPackets, TheLargestPacketWithADescriptorArrivesWithBothInTheirPlaces) {
  const std::vector<std::uint8_t> payload = pattern(kMaxPacket - sizeof(ReplyHeader));
  ReplyHeader h{};
  h.handle = 42;
  int pipe_fds[2];
  ASSERT_EQ(pipe2(pipe_fds, O_CLOEXEC), 0);
  ASSERT_TRUE(send_packet(sv_[0], &h, sizeof h, payload, pipe_fds[1])) << std::strerror(errno);
  close(pipe_fds[1]);
  Packet p;
  int fd = -1;
  ASSERT_TRUE(recv_packet(sv_[1], p, fd, true)) << std::strerror(errno);
  ASSERT_GE(fd, 0);
  EXPECT_EQ(fcntl(fd, F_GETFD) & FD_CLOEXEC, FD_CLOEXEC);
  ASSERT_EQ(write(fd, "x", 1), 1) << "the passed descriptor is the reply's (the pipe), not the memfd";
  char c = 0;
  EXPECT_EQ(read(pipe_fds[0], &c, 1), 1);
  EXPECT_EQ(c, 'x');
  close(fd);
  close(pipe_fds[0]);
  ASSERT_EQ(p.size, kMaxPacket);
  EXPECT_EQ(std::memcmp(p.data.get() + sizeof h, payload.data(), payload.size()), 0);
  // One byte more than the protocol allows is not sent.
  const std::vector<std::uint8_t> too_big(kMaxPacket - sizeof h + 1);
  errno = 0;
  EXPECT_FALSE(send_packet(sv_[0], &h, sizeof h, too_big, -1));
  EXPECT_EQ(errno, EMSGSIZE);
}

TEST_F(ProtocolBigPackets, SmallPacketsStayOneDatagramAsBefore) {
  const std::vector<std::uint8_t> payload = pattern(kInlinePacket - sizeof(RequestHeader));
  RequestHeader h{};
  h.op = 5;
  h.payload = static_cast<std::uint32_t>(payload.size());
  ASSERT_TRUE(send_packet(sv_[0], &h, sizeof h, payload, -1));
  std::vector<std::uint8_t> raw(kInlinePacket + 1);
  EXPECT_EQ(recv(sv_[1], raw.data(), raw.size(), 0), static_cast<ssize_t>(kInlinePacket));
  EXPECT_EQ(std::memcmp(raw.data() + sizeof h, payload.data(), payload.size()), 0);
}

TEST_F(ProtocolBigPackets, ASocketBufferSmallerThanTheInlineLimitSendsByMemfd) {
  const int small = 16384;
  ASSERT_EQ(setsockopt(sv_[0], SOL_SOCKET, SO_SNDBUF, &small, sizeof small), 0);
  const std::vector<std::uint8_t> payload = pattern(100000);
  RequestHeader h{};
  ASSERT_TRUE(send_packet(sv_[0], &h, sizeof h, payload, -1)) << std::strerror(errno);
  Packet p;
  int fd = -1;
  ASSERT_TRUE(recv_packet(sv_[1], p, fd, true));
  ASSERT_EQ(p.size, sizeof h + payload.size());
  EXPECT_EQ(std::memcmp(p.data.get() + sizeof h, payload.data(), payload.size()), 0);
}

TEST_F(ProtocolBigPackets, AnEnvelopeWithoutAMemfdIsRefused) { expect_refused(1000, {}); }

TEST_F(ProtocolBigPackets, AMemfdOfAnotherSizeThanItsEnvelopeSaysIsRefused) {
  expect_refused(200000, {sealed_memfd(100000, true)});
  expect_refused(100000, {sealed_memfd(200000, true), sealed_memfd(10, true)});
}

TEST_F(ProtocolBigPackets, AnEnvelopeClaimingMoreThanTheLargestPacketIsRefused) {
  expect_refused(kMaxPacket + 1, {sealed_memfd(kMaxPacket + 1, true)});
  expect_refused(~std::uint64_t{0}, {sealed_memfd(100, true)});
}

TEST_F(ProtocolBigPackets, ADescriptorThatIsNotASealedMemfdIsRefused) {
  int pipe_fds[2];
  ASSERT_EQ(pipe2(pipe_fds, O_CLOEXEC), 0);
  expect_refused(0, {pipe_fds[0], pipe_fds[1]});
  expect_refused(150000, {sealed_memfd(150000, false)});
  const int dir = open("/", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  ASSERT_GE(dir, 0);
  expect_refused(150000, {dir});
  expect_refused(150000, {sealed_memfd(150000, true)}, /*reserved=*/1);
}

TEST_F(ProtocolBigPackets, SealPacketMakesAMemfdThatLoadPacketTakesBack) {
  const std::vector<std::uint8_t> payload = pattern(300000);
  RequestHeader h{};
  h.op = 8;
  const int fd = seal_packet(&h, sizeof h, payload);
  ASSERT_GE(fd, 0);
  EXPECT_NE(write(fd, "x", 1), 1) << "sealed against writing";
  EXPECT_NE(ftruncate(fd, 10), 0) << "sealed against shrinking";
  Packet p;
  EXPECT_FALSE(load_packet(fd, sizeof h + payload.size() - 1, p.data.get()));
  ASSERT_TRUE(load_packet(fd, sizeof h + payload.size(), p.data.get()));
  EXPECT_EQ(std::memcmp(p.data.get() + sizeof h, payload.data(), payload.size()), 0);
  close(fd);
}

}  // namespace
}  // namespace l6470emu::test
