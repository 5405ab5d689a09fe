// Backend forwarding to `l6470emu serve` over its Unix socket (L6470EMU_SOCKET): one
// connection per process, re-opened after fork(); new files arrive with SCM_RIGHTS. Requests
// go through the connection's shared region (shm_channel.hpp) when they fit and the daemon gave
// one (L6470EMU_SHM=off keeps everything on the socket).
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <mutex>

#include "linux/preload/backend.hpp"
#include "linux/preload/check_exit.hpp"
#include "linux/preload/real.hpp"
#include "linux/preload/state.hpp"
#include "linux/protocol.hpp"
#include "linux/terminal_text.hpp"
#include "linux/shm_channel.hpp"

namespace l6470emu::preload {
namespace {

class RemoteBackend final : public Backend {
 public:
  RemoteBackend(std::string path, const std::string& log) : path_(std::move(path)), log_(log) {
    if (const char* shm = std::getenv("L6470EMU_SHM"); shm && std::strcmp(shm, "off") == 0) use_shared_ = false;
    std::lock_guard lock(m_);
    if (!connect_locked()) {
      if (!refused_.empty())
        log_.line(refused_ + "; no emulated devices");
      else
        log_.line("cannot reach the daemon at " + shown_path() + " (" + std::strerror(errno) +
                  "): no emulated devices; start it with `l6470emu serve`");
      return;
    }
    RequestHeader req{static_cast<std::uint32_t>(Op::hello), 0, 0, kProtocolVersion};
    ReplyHeader rep;
    std::vector<std::uint8_t> payload;
    int fd = -1;
    const bool answered = roundtrip_locked(req, {}, {}, rep, payload, fd, true);
    if (!refused_.empty()) {
      log_.line(refused_ + "; no emulated devices");
      return;
    }
    if (!answered || rep.result < 0) {
      log_.line("the daemon at " + shown_path() + " did not answer the hello (protocol " +
                std::to_string(kProtocolVersion) + ")");
      return;
    }
    nodes_ = decode_catalogue(std::string(payload.begin(), payload.end()));
  }

  ~RemoteBackend() override { disconnect_locked(); }

  const std::vector<DeviceNode>& nodes() override { return nodes_; }

  NewFile open(std::size_t device, bool cloexec) override {
    RequestHeader req{static_cast<std::uint32_t>(Op::open), 0, 0, device | kOpenCloexec};
    ReplyHeader rep;
    int fd = -1;
    std::lock_guard lock(m_);
    if (!roundtrip_locked(req, {}, {}, rep, scratch_, fd, cloexec)) return {-ENODEV, 0, -1, HandleKind::spidev};
    if (rep.result < 0 || fd < 0) {
      if (fd >= 0) real_close_protected(fd);
      return {rep.result < 0 ? rep.result : -EIO, 0, -1, HandleKind::spidev};
    }
    return {0, rep.handle, fd, static_cast<HandleKind>(rep.kind)};
  }

  void closed(std::uint64_t handle) override {
    RequestHeader req{static_cast<std::uint32_t>(Op::closed), 0, handle, 0};
    ReplyHeader rep;
    int fd = -1;
    std::lock_guard lock(m_);
    roundtrip_locked(req, {}, {}, rep, scratch_, fd, true);
  }

  long ioctl(std::uint64_t handle, unsigned long cmd, std::span<std::uint8_t> arg, NewFile* created,
             bool cloexec_created) override {
    RequestHeader req{static_cast<std::uint32_t>(Op::ioctl), static_cast<std::uint32_t>(arg.size()), handle, cmd};
    ReplyHeader rep;
    int fd = -1;
    std::lock_guard lock(m_);
    if (!roundtrip_locked(req, arg, {}, rep, scratch_, fd, cloexec_created)) return -ENODEV;
    if (rep.result >= 0) std::memcpy(arg.data(), scratch_.data(), std::min(arg.size(), scratch_.size()));
    if (fd >= 0) {
      if (created && rep.result >= 0) {
        *created = {0, rep.handle, fd, static_cast<HandleKind>(rep.kind)};
      } else {
        real_close_protected(fd);
      }
    }
    return static_cast<long>(rep.result);
  }

  long spi_message(std::uint64_t handle, std::span<const spi_ioc_transfer> xfers, std::span<const std::uint8_t> tx,
                   std::span<std::uint8_t> rx) override {
    const std::size_t head = xfers.size() * sizeof(spi_ioc_transfer);
    RequestHeader req{static_cast<std::uint32_t>(Op::spi_message), static_cast<std::uint32_t>(head + tx.size()), handle,
                      xfers.size()};
    ReplyHeader rep;
    int fd = -1;
    std::lock_guard lock(m_);
    if (!roundtrip_locked(req, {reinterpret_cast<const std::uint8_t*>(xfers.data()), head}, tx, rep, scratch_, fd, true))
      return -ENODEV;
    if (rep.result >= 0) std::memcpy(rx.data(), scratch_.data(), std::min(rx.size(), scratch_.size()));
    return checked(rep.result);
  }

  long spi_read(std::uint64_t handle, std::span<std::uint8_t> rx) override {
    RequestHeader req{static_cast<std::uint32_t>(Op::spi_read), 0, handle, rx.size()};
    ReplyHeader rep;
    int fd = -1;
    std::lock_guard lock(m_);
    if (!roundtrip_locked(req, {}, {}, rep, scratch_, fd, true)) return -ENODEV;
    if (rep.result >= 0) std::memcpy(rx.data(), scratch_.data(), std::min(rx.size(), scratch_.size()));
    return checked(rep.result);
  }

  long spi_write(std::uint64_t handle, std::span<const std::uint8_t> tx) override {
    RequestHeader req{static_cast<std::uint32_t>(Op::spi_write), static_cast<std::uint32_t>(tx.size()), handle, 0};
    ReplyHeader rep;
    int fd = -1;
    std::lock_guard lock(m_);
    if (!roundtrip_locked(req, tx, {}, rep, scratch_, fd, true)) return -ENODEV;
    return checked(rep.result);
  }

  // The daemon's pwmchips: one per chain (a spidev node each), their channels its npwm.
  std::size_t pwm_chips() override {
    return static_cast<std::size_t>(std::count_if(nodes_.begin(), nodes_.end(),
                                                  [](const DeviceNode& n) { return n.type == DeviceNode::Type::spidev; }));
  }
  std::size_t pwm_channels(std::size_t chain) override {
    std::string text;
    if (pwm_read(chain, -1, PwmAttr::npwm, text) < 0) return 0;
    return static_cast<std::size_t>(std::strtoul(text.c_str(), nullptr, 10));
  }
  long pwm_write(std::size_t chain, int channel, PwmAttr attr, std::string_view text) override {
    RequestHeader req{static_cast<std::uint32_t>(Op::pwm), static_cast<std::uint32_t>(text.size()), chain,
                      pwm_request_arg(channel, attr, true)};
    ReplyHeader rep;
    int fd = -1;
    std::lock_guard lock(m_);
    if (!roundtrip_locked(req, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()}, {}, rep, scratch_, fd,
                          true))
      return -ENODEV;
    return static_cast<long>(rep.result);
  }
  long pwm_read(std::size_t chain, int channel, PwmAttr attr, std::string& out) override {
    RequestHeader req{static_cast<std::uint32_t>(Op::pwm), 0, chain, pwm_request_arg(channel, attr, false)};
    ReplyHeader rep;
    int fd = -1;
    std::lock_guard lock(m_);
    if (!roundtrip_locked(req, {}, {}, rep, scratch_, fd, true)) return -ENODEV;
    if (rep.result >= 0) out.assign(scratch_.begin(), scratch_.end());
    return static_cast<long>(rep.result);
  }

  // check=error on the daemon's board: the reply carries the sanitizer's report instead of the
  // data, and this program's run ends with it (the daemon goes on serving the others).
  long checked(std::int64_t result) {
    if (result == kCheckFailed) end_run_for_check(std::string(scratch_.begin(), scratch_.end()));
    return static_cast<long>(result);
  }

  void before_fork() override { m_.lock(); }
  void after_fork_parent() override { m_.unlock(); }
  void after_fork_child() override {
    // The connection and its region are shared with the parent now: leave them to the parent,
    // open our own on demand.
    disconnect_locked();
    m_.unlock();
  }

 private:
  bool connect_locked() {
    sock_ = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
    if (sock_ < 0) return false;
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (path_.size() >= sizeof addr.sun_path) {
      real_close_protected(sock_);
      sock_ = -1;
      errno = ENAMETOOLONG;
      return false;
    }
    std::memcpy(addr.sun_path, path_.c_str(), path_.size() + 1);
    if (::connect(sock_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
      const int e = errno;
      real_close_protected(sock_);
      sock_ = -1;
      errno = e;
      return false;
    }
    protect_fd(sock_);
    // Only a daemon of our own user (or root's) is told what the program does, or believed.
    if (const std::string foreign = check_server_owner(sock_, path_); !foreign.empty()) {
      refused_ = terminal_safe(foreign);
      disconnect_locked();
      errno = EACCES;
      return false;
    }
    if (use_shared_ && !attach_shared_locked()) {
      disconnect_locked();
      errno = ECONNREFUSED;
      return false;
    }
    return true;
  }

  std::string shown_path() const { return terminal_safe(path_); }

  // A refusal from the daemon (kRefusalKind) as the reply in reply_: remembered for the log.
  bool refused_locked() {
    if (const auto why = decode_refusal(reply_.bytes())) {
      refused_ = "the daemon at " + shown_path() + " refused this program: " + terminal_safe(*why);
      return true;
    }
    return false;
  }

  // Asks the daemon for a shared region; without one (an older daemon, no memfd) every request
  // stays on the socket. False when the daemon refused the connection.
  bool attach_shared_locked() {
    const RequestHeader req{static_cast<std::uint32_t>(Op::attach_shm), 0, 0, 0};
    int fd = -1;
    // A refused connection has its refusal waiting even when the request could not be sent.
    (void)send_packet(sock_, &req, sizeof req, {}, -1);
    if (!recv_packet(sock_, reply_, fd, true)) return true;
    if (refused_locked()) {
      if (fd >= 0) real::close(fd);
      return false;
    }
    ReplyHeader rep;
    if (reply_.size >= sizeof rep) std::memcpy(&rep, reply_.data.get(), sizeof rep);
    if (fd >= 0) {
      if (reply_.size >= sizeof rep && rep.result > 0) shared_ = SharedChannel::attach(fd);
      real::close(fd);  // the mapping stays; nothing of it in the host's descriptor table
    }
    return true;
  }

  void disconnect_locked() {
    shared_.reset();
    if (sock_ >= 0) real_close_protected(sock_);
    sock_ = -1;
  }

  // One request, one reply; reconnects once if the connection was lost (fork, host closed it).
  bool roundtrip_locked(const RequestHeader& req, std::span<const std::uint8_t> a, std::span<const std::uint8_t> b,
                        ReplyHeader& rep, std::vector<std::uint8_t>& payload, int& fd, bool cloexec) {
    for (int attempt = 0; attempt < 2; ++attempt) {
      if (sock_ < 0 && !connect_locked()) return false;
      if (!protected_fd_is(sock_)) {  // the host closed our socket behind our back
        sock_ = -1;
        shared_.reset();
        continue;
      }
      const bool exchanged = exchange_locked(req, a, b, fd, cloexec);
      if (!from_region_ && refused_locked()) {  // the daemon said why it does not serve us
        if (fd >= 0) real::close(fd);
        fd = -1;
        disconnect_locked();
        return false;
      }
      if (!exchanged) {
        disconnect_locked();
        if (req.op != static_cast<std::uint32_t>(Op::hello) && attempt == 0 && errno != EINTR) continue;
        return false;
      }
      std::span<const std::uint8_t> got = reply_.bytes();
      if (from_region_) got = shared_->reply();
      if (got.size() < sizeof rep) {
        disconnect_locked();
        return false;
      }
      std::memcpy(&rep, got.data(), sizeof rep);
      payload.assign(got.begin() + sizeof rep, got.end());
      return true;
    }
    return false;
  }

  // Sends the request and waits for the reply: through the shared region when the request fits
  // (the reply is then in the region, or on the socket when it carries a descriptor or is too
  // large), else on the socket. Sets from_region_. False when the connection is lost.
  bool exchange_locked(const RequestHeader& req, std::span<const std::uint8_t> a, std::span<const std::uint8_t> b,
                       int& fd, bool cloexec) {
    fd = -1;
    from_region_ = false;
    const std::size_t size = sizeof req + a.size() + b.size();
    const bool whole = shared_ && req.op != static_cast<std::uint32_t>(Op::hello) &&
                       req.op != static_cast<std::uint32_t>(Op::open) && size <= kShmAreaBytes;
    const std::function<bool()> alive = [this] { return peer_alive(sock_); };
    if (whole) {
      std::uint8_t* p = shared_->request_area();
      std::memcpy(p, &req, sizeof req);
      if (!a.empty()) std::memcpy(p + sizeof req, a.data(), a.size());
      if (!b.empty()) std::memcpy(p + sizeof req + a.size(), b.data(), b.size());
      shared_->post_request(static_cast<std::uint32_t>(size), 0);
      if (!shared_->wait_reply(kReplySpinNs, alive)) {
        errno = EPIPE;
        return false;
      }
      if (!(shared_->reply_flags() & kShmOnSocket)) {
        from_region_ = true;
        return true;
      }
      return recv_packet(sock_, reply_, fd, cloexec);
    }
    packet_.resize(size);
    std::memcpy(packet_.data(), &req, sizeof req);
    if (!a.empty()) std::memcpy(packet_.data() + sizeof req, a.data(), a.size());
    if (!b.empty()) std::memcpy(packet_.data() + sizeof req + a.size(), b.data(), b.size());
    if (!send_packet(sock_, packet_.data(), packet_.size(), {}, -1)) {
      // The daemon closed the connection; what it sent before (a refusal) is still to be read.
      if (errno == EPIPE || errno == ECONNRESET) {
        const int e = errno;
        if (!recv_packet(sock_, reply_, fd, cloexec)) errno = e;
      }
      return false;
    }
    // With a region, the daemon's thread listens to the region: tell it to read the socket.
    if (shared_) shared_->post_request(0, kShmOnSocket);
    return recv_packet(sock_, reply_, fd, cloexec, kReplySpinNs);
  }

  std::string path_;
  DiagnosticLog log_;
  std::mutex m_;
  int sock_ = -1;
  std::vector<DeviceNode> nodes_;
  std::vector<std::uint8_t> packet_, scratch_;
  Packet reply_;
  bool use_shared_ = true;
  std::string refused_;  // why the daemon (or its owner) is not to be used, "" when it is
  std::unique_ptr<SharedChannel> shared_;
  bool from_region_ = false;  // the last reply is in shared_'s reply area, not in reply_
};

}  // namespace

std::unique_ptr<Backend> make_remote_backend(const std::string& socket_path, const std::string& log) {
  return std::make_unique<RemoteBackend>(socket_path, log);
}

}  // namespace l6470emu::preload
