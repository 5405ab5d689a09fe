// Packets between preload and daemon, and the daemon's request dispatcher.
#include "linux/protocol.hpp"

#include "linux/clock.hpp"
#include "linux/packet_memfd.hpp"
#include "linux/shm_channel.hpp"

#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <sstream>

namespace l6470emu {

std::string encode_catalogue(const std::vector<DeviceNode>& nodes) {
  std::ostringstream o;
  for (const auto& n : nodes)
    o << (n.type == DeviceNode::Type::spidev ? "spidev" : "gpiochip") << ' ' << n.path << ' ' << n.name << ' '
      << n.major << ' ' << n.minor << ' ' << n.bufsiz << '\n';
  return o.str();
}

std::vector<DeviceNode> decode_catalogue(const std::string& text) {
  std::vector<DeviceNode> nodes;
  std::istringstream in(text);
  std::string type;
  while (in >> type) {
    DeviceNode n{type == "spidev" ? DeviceNode::Type::spidev : DeviceNode::Type::gpiochip, {}, {}, 0, 0, 0};
    in >> n.path >> n.name >> n.major >> n.minor >> n.bufsiz;
    if (!in) break;
    nodes.push_back(std::move(n));
  }
  return nodes;
}

std::vector<std::uint8_t> encode_refusal(const std::string& why) {
  ReplyHeader h{};
  h.result = -ECONNREFUSED;
  h.kind = kRefusalKind;
  h.payload = static_cast<std::uint32_t>(why.size());
  std::vector<std::uint8_t> p(sizeof h + why.size());
  std::memcpy(p.data(), &h, sizeof h);
  std::memcpy(p.data() + sizeof h, why.data(), why.size());
  return p;
}

std::optional<std::string> decode_refusal(std::span<const std::uint8_t> packet) {
  ReplyHeader h;
  if (packet.size() < sizeof h) return std::nullopt;
  std::memcpy(&h, packet.data(), sizeof h);
  if (h.kind != kRefusalKind || h.result != -ECONNREFUSED) return std::nullopt;
  const std::size_t n = std::min<std::size_t>(packet.size() - sizeof h, 512);
  return std::string(reinterpret_cast<const char*>(packet.data()) + sizeof h, n);
}

std::string check_server_owner(int sock, const std::string& path) {
  ucred peer{};
  socklen_t len = sizeof peer;
  if (getsockopt(sock, SOL_SOCKET, SO_PEERCRED, &peer, &len) != 0)
    return "cannot tell who serves " + path + " (" + std::strerror(errno) + "): not talking to it";
  const uid_t me = geteuid();
  if (peer.uid == me || peer.uid == 0) return "";
  return "the socket " + path + " is served by user " + std::to_string(peer.uid) + " (pid " + std::to_string(peer.pid) +
         "), not by you (user " + std::to_string(me) + ") or root: not talking to it";
}

namespace {

// One datagram: `iov` with up to two descriptors (-1: none) in one SCM_RIGHTS message.
bool send_datagram(int sock, iovec* iov, std::size_t iovlen, int fd0, int fd1) {
  msghdr msg{};
  msg.msg_iov = iov;
  msg.msg_iovlen = iovlen;
  alignas(cmsghdr) char control[CMSG_SPACE(2 * sizeof(int))] = {};
  if (fd0 >= 0) {
    const int fds[2] = {fd0, fd1};
    const std::size_t count = fd1 >= 0 ? 2 : 1;
    msg.msg_control = control;
    msg.msg_controllen = CMSG_SPACE(count * sizeof(int));
    cmsghdr* c = CMSG_FIRSTHDR(&msg);
    c->cmsg_level = SOL_SOCKET;
    c->cmsg_type = SCM_RIGHTS;
    c->cmsg_len = CMSG_LEN(count * sizeof(int));
    std::memcpy(CMSG_DATA(c), fds, count * sizeof(int));
  }
  for (;;) {
    const ssize_t n = sendmsg(sock, &msg, MSG_NOSIGNAL);
    if (n >= 0) return true;
    if (errno != EINTR) return false;
  }
}

// The packet in a sealed memfd, under a BigPacketEnvelope: the memfd first, then `fd`.
bool send_big_packet(int sock, const void* header, std::size_t header_size, std::span<const std::uint8_t> payload,
                     int fd) {
  const int memfd = seal_packet(header, header_size, payload);
  if (memfd < 0) return false;
  BigPacketEnvelope envelope;
  envelope.size = header_size + payload.size();
  iovec iov{&envelope, sizeof envelope};
  const bool sent = send_datagram(sock, &iov, 1, memfd, fd);
  const int e = errno;
  ::close(memfd);  // the peer has its copy now (or is gone)
  errno = e;
  return sent;
}

}  // namespace

bool send_packet(int sock, const void* header, std::size_t header_size, std::span<const std::uint8_t> payload, int fd) {
  if (header_size + payload.size() > kInlinePacket) return send_big_packet(sock, header, header_size, payload, fd);
  iovec iov[2] = {{const_cast<void*>(header), header_size},
                  {const_cast<std::uint8_t*>(payload.data()), payload.size()}};
  if (send_datagram(sock, iov, payload.empty() ? 1 : 2, fd, -1)) return true;
  // A socket buffer smaller than kInlinePacket (a lowered wmem_default): the memfd way.
  if (errno == EMSGSIZE) return send_big_packet(sock, header, header_size, payload, fd);
  return false;
}

bool recv_packet(int sock, Packet& packet, int& fd, bool cloexec, std::int64_t spin_ns) {
  fd = -1;
  packet.size = 0;
  const std::int64_t spin_until = spin_ns > 0 ? monotonic_ns() + spin_ns : 0;
  bool reset_seen = false, spin_once = false;
  // One receive, no peek: the buffer is as large as the largest packet can be (kMaxPacket).
  for (;;) {
    iovec iov{packet.data.get(), kMaxPacket};
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    alignas(cmsghdr) char control[CMSG_SPACE(2 * sizeof(int))] = {};
    msg.msg_control = control;
    msg.msg_controllen = sizeof control;
    // Spinning a few microseconds before sleeping saves two scheduler wake-ups per round trip
    // when the other side answers quickly (it usually does: one SPI message is microseconds).
    const bool spin = spin_once || (spin_until != 0 && monotonic_ns() < spin_until);
    spin_once = false;
    const ssize_t n = recvmsg(sock, &msg, (cloexec ? MSG_CMSG_CLOEXEC : 0) | (spin ? MSG_DONTWAIT : 0));
    if (n < 0 && (errno == EINTR || (spin && (errno == EAGAIN || errno == EWOULDBLOCK)))) continue;
    // A peer that closed with our last packet unread reports the reset once, before the packets
    // it sent are received (a refusal): look once more, without waiting.
    if (n < 0 && errno == ECONNRESET && !reset_seen) {
      reset_seen = true;
      spin_once = true;
      continue;
    }
    if (n <= 0) return false;
    // Every descriptor received is owned: the first is the packet's (after a big packet's memfd,
    // which comes first under a BigPacketEnvelope), any more (a peer that sent several) are
    // closed at once, never kept open for good.
    BigPacketEnvelope envelope{};
    envelope.magic = 0;
    if (static_cast<std::size_t>(n) == sizeof envelope) std::memcpy(&envelope, packet.data.get(), sizeof envelope);
    const bool big = envelope.magic == kBigPacketMagic;
    int memfd = -1;
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SCM_RIGHTS || c->cmsg_len < CMSG_LEN(0)) continue;
      const std::size_t count = (c->cmsg_len - CMSG_LEN(0)) / sizeof(int);
      for (std::size_t i = 0; i < count; ++i) {
        int received = -1;
        std::memcpy(&received, CMSG_DATA(c) + i * sizeof(int), sizeof received);
        if (big && memfd < 0)
          memfd = received;
        else if (fd < 0)
          fd = received;
        else
          ::close(received);
      }
    }
    if (msg.msg_flags & MSG_TRUNC) {  // no packet: nothing that came with it is kept
      if (memfd >= 0) ::close(memfd);
      if (fd >= 0) ::close(fd);
      fd = -1;
      errno = EMSGSIZE;
      return false;
    }
    if (big) {
      // The packet is the memfd's: checked (a memfd, sealed, of the size said, at most
      // kMaxPacket) and read whole into the buffer, or the packet is refused with all it carried.
      const bool loaded = envelope.reserved == 0 && load_packet(memfd, envelope.size, packet.data.get());
      if (memfd >= 0) ::close(memfd);
      if (!loaded) {
        if (fd >= 0) ::close(fd);
        fd = -1;
        errno = EPROTO;
        return false;
      }
      packet.size = static_cast<std::size_t>(envelope.size);
      return true;
    }
    packet.size = static_cast<std::size_t>(n);
    return true;
  }
}

namespace {

// check=error: the client's run ends with the report (its preload exits); the daemon says so in
// its own log and goes on serving the others.
void failed_check(DeviceBoard& board, const std::string& report, std::vector<std::uint8_t>& out) {
  const std::string first = report.substr(0, report.find('\n'));
  board.log().line(first.substr(std::min(first.size(), first.find("driver sanitizer"))) +
                   " [check=error: the client's run ends]");
  out.assign(report.begin(), report.end());
}

}  // namespace

void serve_request(DeviceBoard& board, const ControlHandler& control, std::span<const std::uint8_t> packet, ReplyHeader& reply,
                   std::vector<std::uint8_t>& out, int& pass_fd, const std::function<bool()>& client_alive) {
  reply = {};
  out.clear();
  pass_fd = -1;
  RequestHeader req;
  if (packet.size() < sizeof req) {
    reply.result = -EPROTO;
    return;
  }
  std::memcpy(&req, packet.data(), sizeof req);
  const std::span<const std::uint8_t> payload = packet.subspan(sizeof req);
  if (payload.size() != req.payload) {
    reply.result = -EPROTO;
    return;
  }
  switch (static_cast<Op>(req.op)) {
    case Op::hello: {
      if (req.arg != kProtocolVersion) {
        reply.result = -EPROTONOSUPPORT;
        return;
      }
      const std::string cat = encode_catalogue(board.nodes());
      out.assign(cat.begin(), cat.end());
      return;
    }
    case Op::open: {
      const NewFile f = board.open(static_cast<std::size_t>(req.arg & ~kOpenCloexec), true);
      reply.result = f.result;
      reply.handle = f.handle;
      reply.kind = static_cast<std::uint32_t>(f.kind);
      pass_fd = f.fd;
      return;
    }
    case Op::closed:
      board.closed(req.handle);
      return;
    case Op::ioctl: {
      out.assign(payload.begin(), payload.end());
      NewFile created;
      reply.result = board.ioctl(req.handle, static_cast<unsigned long>(req.arg), out, &created);
      if (reply.result >= 0 && created.fd >= 0) {
        reply.handle = created.handle;
        reply.kind = static_cast<std::uint32_t>(created.kind);
        pass_fd = created.fd;
      }
      return;
    }
    case Op::spi_message: {
      const std::size_t n = static_cast<std::size_t>(req.arg);
      if (n > kMaxTransfers) {  // no spidev ioctl can carry more (a raw client's packet)
        reply.result = -EINVAL;
        return;
      }
      if (payload.size() < n * sizeof(spi_ioc_transfer)) {
        reply.result = -EPROTO;
        return;
      }
      std::vector<spi_ioc_transfer> xfers(n);
      if (n > 0) std::memcpy(xfers.data(), payload.data(), n * sizeof(spi_ioc_transfer));
      const auto tx = payload.subspan(n * sizeof(spi_ioc_transfer));
      std::uint64_t rx_len = 0;
      for (const auto& x : xfers)
        if (x.rx_buf) rx_len += x.len;
      if (rx_len > kMaxMessage) {
        reply.result = -EMSGSIZE;
        return;
      }
      out.assign(static_cast<std::size_t>(rx_len), 0);
      std::string report;
      reply.result = board.spi_message(req.handle, xfers, tx, out, &report, client_alive);
      if (reply.result < 0) out.clear();
      if (reply.result == kCheckFailed) failed_check(board, report, out);  // the client ends with it
      return;
    }
    case Op::spi_read: {
      if (req.arg > kMaxMessage) {
        reply.result = -EMSGSIZE;
        return;
      }
      out.assign(static_cast<std::size_t>(req.arg), 0);
      std::string report;
      reply.result = board.spi_read(req.handle, out, &report, client_alive);
      if (reply.result < 0) out.clear();
      if (reply.result == kCheckFailed) failed_check(board, report, out);
      return;
    }
    case Op::spi_write: {
      std::string report;
      reply.result = board.spi_write(req.handle, payload, &report, client_alive);
      if (reply.result == kCheckFailed) failed_check(board, report, out);
      return;
    }
    case Op::control: {
      std::string text;
      const std::string command(payload.begin(), payload.end());
      reply.result = control ? control(command, text) : 1;
      out.assign(text.begin(), text.end());
      return;
    }
    case Op::attach_shm:  // a matter of the connection (serve/daemon.cpp), not of the board
      break;
    case Op::pwm: {
      const int channel = static_cast<int>(static_cast<std::uint32_t>(req.arg)) - 1;
      const std::uint64_t attr = (req.arg >> 32) & 0xFF;
      if (attr > static_cast<std::uint64_t>(PwmAttr::polarity)) {  // the chain: pwm_write and pwm_read check it
        reply.result = -EINVAL;
        return;
      }
      if ((req.arg >> 40) & 1) {
        const std::string text(payload.begin(), payload.end());
        reply.result = board.pwm_write(static_cast<std::size_t>(req.handle), channel, static_cast<PwmAttr>(attr), text);
      } else {
        std::string text;
        reply.result = board.pwm_read(static_cast<std::size_t>(req.handle), channel, static_cast<PwmAttr>(attr), text);
        out.assign(text.begin(), text.end());
      }
      return;
    }
  }
  reply.result = -EPROTO;
}

SharedOutcome serve_shared_request(DeviceBoard& board, const ControlHandler& control, SharedChannel& channel,
                                   std::uint8_t* scratch, ReplyHeader& reply, std::vector<std::uint8_t>& out,
                                   int& pass_fd, const std::function<bool()>& client_alive) {
  std::uint32_t flags = 0;
  const std::size_t n = channel.take_request(scratch, flags);
  pass_fd = -1;
  if (flags & kShmOnSocket) return SharedOutcome::request_on_socket;
  try {
    serve_request(board, control, {scratch, n}, reply, out, pass_fd, client_alive);
  } catch (const std::exception&) {
    reply = {};
    reply.result = -ENOMEM;
    out.clear();
  }
  reply.payload = static_cast<std::uint32_t>(out.size());
  if (pass_fd >= 0 || !SharedChannel::reply_fits(sizeof reply + out.size())) return SharedOutcome::reply_on_socket;
  channel.post_reply({reinterpret_cast<const std::uint8_t*>(&reply), sizeof reply}, out, 0);
  return SharedOutcome::replied;
}

}  // namespace l6470emu
