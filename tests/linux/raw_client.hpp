// Clients of `l6470emu serve` that speak its protocol by hand, for the tests that abuse the
// daemon: connect, say hello and read what comes back (an answer or a refusal), and the dead
// client that attaches its shared region, leaves a packet unread on the socket and dies.
#pragma once

#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "linux/protocol.hpp"

namespace l6470emu::test {

/// A connected SOCK_SEQPACKET socket to `path`, or -1.
inline int connect_raw(const std::string& path) {
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

/// What the daemon said to a hello: nothing (it closed the connection or stayed silent for 5 s),
/// an answer (result >= 0) or a refusal and its reason.
struct HelloOutcome {
  bool answered = false;
  std::optional<std::string> refusal;
};

inline HelloOutcome say_hello(int fd) {
  HelloOutcome o;
  const RequestHeader req{static_cast<std::uint32_t>(Op::hello), 0, 0, kProtocolVersion};
  (void)send(fd, &req, sizeof req, MSG_NOSIGNAL);  // a refused connection may be closed already
  timeval tv{5, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  std::vector<std::uint8_t> buf(1 << 16);
  ssize_t n = recv(fd, buf.data(), buf.size(), 0);
  if (n < 0 && errno == ECONNRESET) n = recv(fd, buf.data(), buf.size(), MSG_DONTWAIT);  // the refusal follows
  if (n < static_cast<ssize_t>(sizeof(ReplyHeader))) return o;
  buf.resize(static_cast<std::size_t>(n));
  o.refusal = decode_refusal(buf);
  ReplyHeader h;
  std::memcpy(&h, buf.data(), sizeof h);
  o.answered = !o.refusal && h.result >= 0;
  return o;
}

/// Attaches a shared region on `fd` (the daemon's thread then waits on the region, not the
/// socket). True when the daemon gave one.
inline bool attach_region(int fd) {
  const RequestHeader req{static_cast<std::uint32_t>(Op::attach_shm), 0, 0, 0};
  if (send(fd, &req, sizeof req, MSG_NOSIGNAL) != static_cast<ssize_t>(sizeof req)) return false;
  std::uint8_t buf[256];
  iovec iov{buf, sizeof buf};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(int))] = {};
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  const ssize_t n = recvmsg(fd, &msg, MSG_CMSG_CLOEXEC);
  int region = -1;
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c))
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_RIGHTS) std::memcpy(&region, CMSG_DATA(c), sizeof region);
  if (region >= 0) close(region);
  ReplyHeader h{};
  if (n >= static_cast<ssize_t>(sizeof h)) std::memcpy(&h, buf, sizeof h);
  return region >= 0 && h.result > 0;
}

/// A process that opens `connections` connections to `socket`, attaches a shared region on each,
/// writes one packet on each socket (which the daemon, waiting on the region, never reads) and
/// dies without closing anything. Returns how many connections got their region (-1: it crashed).
inline int dead_clients_with_unread_packets(const std::string& socket, int connections) {
  int pipefd[2];
  if (pipe(pipefd) != 0) return -1;
  const pid_t pid = fork();
  if (pid == 0) {
    close(pipefd[0]);
    int attached = 0;
    for (int i = 0; i < connections; ++i) {
      const int fd = connect_raw(socket);
      if (fd < 0 || !attach_region(fd)) continue;
      const RequestHeader req{static_cast<std::uint32_t>(Op::hello), 0, 0, kProtocolVersion};
      if (send(fd, &req, sizeof req, MSG_NOSIGNAL) == static_cast<ssize_t>(sizeof req)) ++attached;
    }
    (void)!write(pipefd[1], &attached, sizeof attached);
    _exit(0);  // every connection ends here, its packet unread
  }
  close(pipefd[1]);
  int attached = -1;
  if (read(pipefd[0], &attached, sizeof attached) != static_cast<ssize_t>(sizeof attached)) attached = -1;
  close(pipefd[0]);
  waitpid(pid, nullptr, 0);
  return attached;
}

/// A process that holds `connections` connections to `socket`, each after a hello, until it is
/// destroyed: how many were answered and refused, and the first refusal's reason.
class ConnectionHolder {
 public:
  ConnectionHolder(const std::string& socket, int connections) {
    int report[2];
    if (pipe(report) != 0) return;
    pid_ = fork();
    if (pid_ == 0) {
      close(report[0]);
      int counts[2] = {0, 0};
      std::string first;
      std::vector<int> held;
      for (int i = 0; i < connections; ++i) {
        const int fd = connect_raw(socket);
        if (fd < 0) continue;
        const HelloOutcome o = say_hello(fd);
        counts[0] += o.answered ? 1 : 0;
        counts[1] += o.refusal ? 1 : 0;
        if (o.refusal && first.empty()) first = *o.refusal;
        held.push_back(fd);
      }
      (void)!write(report[1], counts, sizeof counts);
      (void)!write(report[1], first.data(), first.size());
      close(report[1]);
      for (;;) pause();  // until the test lets go
    }
    close(report[1]);
    int counts[2] = {0, 0};
    if (read(report[0], counts, sizeof counts) == static_cast<ssize_t>(sizeof counts)) {
      answered_ = counts[0];
      refused_ = counts[1];
      char buf[1024];
      for (ssize_t n; (n = read(report[0], buf, sizeof buf)) > 0;) first_refusal_.append(buf, static_cast<std::size_t>(n));
    }
    close(report[0]);
  }
  ~ConnectionHolder() {
    if (pid_ <= 0) return;
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  ConnectionHolder(const ConnectionHolder&) = delete;
  ConnectionHolder& operator=(const ConnectionHolder&) = delete;
  pid_t pid() const { return pid_; }
  int answered() const { return answered_; }
  int refused() const { return refused_; }
  const std::string& first_refusal() const { return first_refusal_; }

 private:
  pid_t pid_ = -1;
  int answered_ = 0, refused_ = 0;
  std::string first_refusal_;
};

}  // namespace l6470emu::test
