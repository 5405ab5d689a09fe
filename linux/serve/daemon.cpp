// The serve daemon: socket set-up, accept loop, one thread per connection (its requests from the
// socket or from a shared region), clean shutdown.
#include "board/coverage_file.hpp"
#include "linux/serve/daemon.hpp"

#include <poll.h>
#include <pthread.h>
#include <sys/stat.h>
#include <signal.h>
#include <sys/signalfd.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>

#include "daisychain/chip_numbering.hpp"
#include "linux/device_board.hpp"
#include "linux/protocol.hpp"
#include "linux/serve/control.hpp"
#include "linux/serve/control_words.hpp"
#include "linux/serve/ctl_reply.hpp"
#include "linux/terminal_text.hpp"
#include "linux/shm_channel.hpp"

namespace l6470emu {
namespace {

bool fill_address(const std::string& path, sockaddr_un& addr) {
  addr = {};
  addr.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof addr.sun_path) return false;
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  return true;
}

int connect_to(const std::string& path) {
  sockaddr_un addr;
  if (!fill_address(path, addr)) {
    errno = ENAMETOOLONG;
    return -1;
  }
  const int s = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
  if (s < 0) return -1;
  if (connect(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    const int e = errno;
    close(s);
    errno = e;
    return -1;
  }
  return s;
}

/// Connections served at once; more are refused (each one is a thread and a packet buffer).
constexpr std::size_t kMaxClients = 256;
/// Connections of one process (SO_PEERCRED pid) served at once: the preload needs one (one more
/// for a moment after fork), ctl one; the cap keeps one process from taking every slot.
constexpr std::size_t kMaxClientsPerProcess = 16;
/// How long SIGTERM waits for the connections to end (a thread sleeping on its region's futex
/// ends within kShmAliveCheckMs). One still waiting out a message's bus time is not waited for.
constexpr int kStopWaitMs = 3000;
/// Stack of a connection thread: serving a request needs little (buffers live on the heap).
constexpr std::size_t kConnectionStack = 256 * 1024;

struct Connection {
  int fd = -1;
  pthread_t thread{};
  bool done = false;  // under the connections' lock
  pid_t pid = 0;
  std::atomic<bool> shared{false};                // requests come through a shared region
  std::atomic<std::uint64_t> shared_requests{0};  // served from the region
  std::atomic<std::uint64_t> socket_requests{0};  // received on the socket
};

/// Starts `body` on a thread with a small stack. Returns false (errno set) when it cannot.
bool start_thread(pthread_t& thread, std::function<void()> body) {
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr, kConnectionStack);
  auto* task = new std::function<void()>(std::move(body));
  const int r = pthread_create(
      &thread, &attr,
      [](void* p) -> void* {
        std::unique_ptr<std::function<void()>> f(static_cast<std::function<void()>*>(p));
        (*f)();
        return nullptr;
      },
      task);
  pthread_attr_destroy(&attr);
  if (r != 0) {
    delete task;
    errno = r;
    return false;
  }
  return true;
}

/// Tells a client why it is not served (kRefusalKind), without waiting, then closes the connection.
void refuse(int sock, const std::string& why) {
  const std::vector<std::uint8_t> p = encode_refusal(why);
  (void)send(sock, p.data(), p.size(), MSG_DONTWAIT | MSG_NOSIGNAL);
  close(sock);
}

/// Sends a reply on the socket (closing `pass_fd` after); false when the client is gone.
bool send_reply(int sock, const ReplyHeader& reply, const std::vector<std::uint8_t>& payload, int pass_fd) {
  const bool sent = send_packet(sock, &reply, sizeof reply, payload, pass_fd);
  if (pass_fd >= 0) close(pass_fd);  // the client has its copy now (or is gone)
  return sent;
}

/// Op::attach_shm: a shared region for this connection (one only), its memfd in the reply.
bool attach_shared(Connection& c, std::unique_ptr<SharedChannel>& shared) {
  ReplyHeader reply{};
  int fd = -1;
  if (shared) {
    reply.result = -EALREADY;
  } else if (auto made = SharedChannel::create(fd)) {
    shared = std::move(made);
    reply.result = static_cast<std::int64_t>(SharedChannel::region_bytes());
  } else {
    reply.result = -errno;
  }
  if (!send_reply(c.fd, reply, {}, fd)) return false;
  if (shared) c.shared = true;
  return true;
}

/// Serves one connection until the client leaves (or the daemon shuts the socket down). On the
/// socket until the client attaches a shared region, then from the region: the thread spins
/// briefly for the next request and then sleeps on the region's futex, looking every
/// kShmAliveCheckMs whether the client is still there, so a client killed at any moment (even
/// while the thread sleeps on its futex) ends only its own connection.
void serve_connection(DeviceBoard& board, const ControlHandler& control, Connection& c,
                      const std::atomic<bool>& stopping) {
  Packet packet;
  std::vector<std::uint8_t> payload;
  ReplyHeader reply;
  std::unique_ptr<SharedChannel> shared;
  std::unique_ptr<std::uint8_t[]> scratch(new std::uint8_t[kShmAreaBytes]);
  const std::function<bool()> alive = [&c, &stopping] { return !stopping && peer_alive(c.fd); };
  for (;;) {
    int pass_fd = -1;
    if (shared) {
      if (!shared->wait_request(kRequestSpinNs, alive)) break;
      const SharedOutcome done =
          serve_shared_request(board, control, *shared, scratch.get(), reply, payload, pass_fd, alive);
      if (done != SharedOutcome::request_on_socket) {
        ++c.shared_requests;
        if (done == SharedOutcome::reply_on_socket) {
          if (!send_reply(c.fd, reply, payload, pass_fd)) break;
          shared->post_reply({}, {}, kShmOnSocket);
        }
        continue;
      }
    }
    int passed = -1;
    if (!recv_packet(c.fd, packet, passed, true, shared ? 0 : kRequestSpinNs)) break;
    if (passed >= 0) close(passed);  // clients never send descriptors
    ++c.socket_requests;
    if (RequestHeader req; packet.size == sizeof req) {
      std::memcpy(&req, packet.data.get(), sizeof req);
      if (req.op == static_cast<std::uint32_t>(Op::attach_shm) && req.payload == 0) {
        if (!attach_shared(c, shared)) break;
        continue;
      }
    }
    try {
      serve_request(board, control, packet.bytes(), reply, payload, pass_fd, alive);
    } catch (const std::exception&) {
      reply = {};
      reply.result = -ENOMEM;
      payload.clear();
    }
    reply.payload = static_cast<std::uint32_t>(payload.size());
    if (!send_reply(c.fd, reply, payload, pass_fd)) break;  // client killed mid-request: drop it, keep serving others
  }
}

/// `ctl clients`: who is connected and how each is served (a connection that ended but is not
/// reaped yet is left out). The caller holds the connections' lock.
std::string describe_clients(const std::list<Connection>& connections) {
  std::ostringstream o;
  std::size_t n = 0;
  for (const Connection& c : connections) n += c.done ? 0 : 1;
  o << n << (n == 1 ? " client\n" : " clients\n");
  for (const Connection& c : connections) {
    if (c.done) continue;
    o << "pid " << c.pid << ": ";
    if (c.shared)
      o << "shared memory, " << c.shared_requests << " requests through it, " << c.socket_requests
        << " through the socket\n";
    else
      o << "socket, " << c.socket_requests << (c.socket_requests == 1 ? " request\n" : " requests\n");
  }
  return o.str();
}

}  // namespace

std::string default_socket_path() {
  if (const char* s = std::getenv("L6470EMU_SOCKET"); s && *s) return s;
  if (const char* r = std::getenv("XDG_RUNTIME_DIR"); r && *r) return std::string(r) + "/l6470emu.sock";
  return "/tmp/l6470emu-" + std::to_string(getuid()) + ".sock";
}

int run_daemon(const BoardConfig& config, const std::string& socket_path, std::ostream& out, std::ostream& err,
               const FrontEnds& front_ends, const std::string& preload_library) {
  sockaddr_un addr;
  if (!fill_address(socket_path, addr)) {
    err << "l6470emu serve: socket path too long or empty: " << socket_path << "\n";
    return 1;
  }
  // Only a stale socket of our own (a killed daemon's) is replaced; anything else at the path is
  // someone else's: a regular file, a directory, a socket another user put there first.
  if (struct stat st{}; lstat(socket_path.c_str(), &st) == 0) {
    if (!S_ISSOCK(st.st_mode)) {
      err << "l6470emu serve: " << socket_path << " exists and is not a socket; not touching it\n";
      return 1;
    }
    if (st.st_uid != geteuid()) {
      err << "l6470emu serve: " << socket_path << " belongs to user " << st.st_uid
          << ", not to us; choose another path with --socket\n";
      return 1;
    }
    if (const int probe = connect_to(socket_path); probe >= 0) {
      close(probe);
      err << "l6470emu serve: another daemon is already serving " << socket_path << "\n";
      return 1;
    }
    unlink(socket_path.c_str());
  }

  // Signals arrive through a signalfd; every thread started from here on has them blocked.
  sigset_t mask;
  sigemptyset(&mask);
  sigaddset(&mask, SIGINT);
  sigaddset(&mask, SIGTERM);
  sigaddset(&mask, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &mask, nullptr);
  signal(SIGPIPE, SIG_IGN);
  const int sfd = signalfd(-1, &mask, SFD_CLOEXEC);

  // The socket is 0600 from birth (whatever the umask): whoever can connect can record files as
  // the daemon's user, so only that user (and root) may, and peers are checked again at accept.
  const int listener = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
  const mode_t old_umask = umask(0177);
  const bool bound = listener >= 0 && bind(listener, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
  umask(old_umask);
  if (!bound || listen(listener, 64) != 0) {
    err << "l6470emu serve: cannot listen on " << socket_path << ": " << std::strerror(errno) << "\n";
    if (listener >= 0) close(listener);
    return 1;
  }

  DiagnosticLog log(config.log);
  DeviceBoard board(config, log);
  if (!config.trace.empty()) {
    if (const std::string error = board.start_recording_all(config.trace); !error.empty()) {
      err << "l6470emu serve: cannot record: " << error << "\n";
      close(listener);
      unlink(socket_path.c_str());
      if (sfd >= 0) close(sfd);
      return 1;
    }
  }
  if (!config.coverage.empty()) board.enable_coverage();
  board.start_pump();
  std::shared_ptr<void> kept;
  if (front_ends) {
    std::string error;
    kept = front_ends(board, out, error);
    if (!error.empty()) {
      err << "l6470emu serve: " << error << "\n";
      kept.reset();
      close(listener);
      unlink(socket_path.c_str());
      if (sfd >= 0) close(sfd);
      return 1;
    }
  }
  std::list<Connection> connections;
  std::mutex connections_mutex;
  std::condition_variable connection_ended;
  std::atomic<bool> stopping{false};
  std::mutex control_mutex;  // ctl commands one at a time
  const ControlHandler control = [&](const std::string& command, std::string& text) {
    std::lock_guard lock(control_mutex);
    const std::vector<std::string> words = split_control_words(command);
    if (!words.empty() && words[0] == "clients") {
      // `clients` names no chip, so ctl's --number-from (passed after the command word) changes nothing.
      const bool only_numbering =
          words.size() == 1 || (words.size() == 3 && words[1] == "--number-from" && number_from_named(words[2]));
      if (!only_numbering) {
        text = "ctl: usage: clients (it lists every connected program: no --chip, --chain or other word)\n";
        return 2;
      }
      std::lock_guard l(connections_mutex);
      text = describe_clients(connections);
      return 0;
    }
    return run_control(board, command, text);
  };

  out << "l6470emu serve: listening on " << socket_path << "\n";
  for (std::size_t i = 0; i < board.chain_count(); ++i) out << "  " << board.chain_summary(i) << "\n";
  out << "  " << (config.time.virtual_time ? std::string("virtual time") : "wall clock x " + std::to_string(config.time.scale))
      << "\n";
  out << "  " << describe_numbering(config.numbering) << " (ctl and diagnostics; numbering=)\n";
  for (std::size_t i = 0; i < board.chain_count(); ++i)
    if (const std::string path = board.recording_path(i); !path.empty()) out << "  recording to " << path << "\n";
  out << "run programs with: LD_PRELOAD=" << (preload_library.empty() ? "<path>/libl6470emu-preload.so" : preload_library)
      << " L6470EMU_SOCKET=" << socket_path << " <program>\n";
  out.flush();

  bool warned_descriptors = false, warned_clients = false;
  pid_t warned_process = 0;
  for (;;) {
    pollfd fds[2] = {{listener, POLLIN, 0}, {sfd, POLLIN, 0}};
    const int n = poll(fds, 2, 1000);
    if (n < 0 && errno != EINTR) break;
    if (fds[1].revents & POLLIN) break;
    {
      // Reap finished connection threads.
      std::lock_guard lock(connections_mutex);
      for (auto it = connections.begin(); it != connections.end();) {
        if (it->done) {
          pthread_join(it->thread, nullptr);
          close(it->fd);
          it = connections.erase(it);
        } else {
          ++it;
        }
      }
    }
    if (!(fds[0].revents & POLLIN)) continue;
    const int c = accept4(listener, nullptr, nullptr, SOCK_CLOEXEC);
    if (c < 0) {
      if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS || errno == ENOMEM) {
        // Out of descriptors: the listener stays readable, so wait instead of spinning.
        if (!warned_descriptors) log.line("serve: out of file descriptors (" + std::string(std::strerror(errno)) +
                                          "): new clients wait until some leave");
        warned_descriptors = true;
        poll(nullptr, 0, 100);
      }
      continue;
    }
    warned_descriptors = false;
    ucred peer{};
    socklen_t len = sizeof peer;
    if (getsockopt(c, SOL_SOCKET, SO_PEERCRED, &peer, &len) != 0 || (peer.uid != geteuid() && peer.uid != 0)) {
      log.line("serve: refused a client of user " + std::to_string(peer.uid) + " (pid " + std::to_string(peer.pid) +
               "): only user " + std::to_string(geteuid()) + " and root may use this daemon");
      refuse(c, "the daemon at " + socket_path + " serves only user " + std::to_string(geteuid()) +
                    " and root, not user " + std::to_string(peer.uid));
      continue;
    }
    std::lock_guard lock(connections_mutex);
    std::size_t of_process = 0;
    for (const Connection& k : connections) of_process += !k.done && k.pid == peer.pid ? 1 : 0;
    if (connections.size() >= kMaxClients) {
      if (!warned_clients) log.line("serve: " + std::to_string(kMaxClients) + " clients connected; refusing more until some leave");
      warned_clients = true;
      refuse(c, "the daemon at " + socket_path + " already serves " + std::to_string(kMaxClients) +
                    " clients, the most it serves at once; try again when some have left");
      continue;
    }
    warned_clients = false;
    if (of_process >= kMaxClientsPerProcess) {
      if (warned_process != peer.pid)
        log.line("serve: process " + std::to_string(peer.pid) + " has " + std::to_string(of_process) +
                 " connections, the most one process may have; refusing more of them");
      warned_process = peer.pid;
      refuse(c, "process " + std::to_string(peer.pid) + " already has " + std::to_string(of_process) +
                    " connections to the daemon at " + socket_path + ", the most one process may have (" +
                    std::to_string(kMaxClientsPerProcess) + ")");
      continue;
    }
    Connection& conn = connections.emplace_back();
    conn.fd = c;
    conn.pid = peer.pid;
    if (!start_thread(conn.thread, [&board, &control, &conn, &connections_mutex, &connection_ended, &stopping, &log] {
          // Out of memory (a tight ulimit -v): this client is refused with the reason, the
          // daemon serves the others on.
          try {
            serve_connection(board, control, conn, stopping);
          } catch (const std::bad_alloc&) {
            log.line("serve: out of memory for a client's buffers; refused it");
            refuse(conn.fd, "the daemon is out of memory for this client's buffers; try again when others have left");
          } catch (const std::exception& e) {
            log.line(std::string("serve: a client's connection ended: ") + e.what());
          }
          std::lock_guard l(connections_mutex);
          conn.done = true;
          connection_ended.notify_all();
        })) {
      const std::string why = std::strerror(errno);
      log.line("serve: cannot start a thread for a client (" + why + "); refused");
      refuse(c, "the daemon at " + socket_path + " cannot start a thread for this client (" + why + ")");
      connections.pop_back();
    }
  }

  out << "l6470emu serve: stopping\n";
  out.flush();
  close(listener);
  unlink(socket_path.c_str());
  // Every connection ends: its socket is shut down (a thread in recvmsg or sendmsg returns, one
  // sleeping on its region's futex sees the hang-up at its next look) and `stopping` is set.
  // A thread still waiting out a long message's bus time is not waited for.
  stopping = true;
  std::size_t stuck = 0;
  {
    std::unique_lock lock(connections_mutex);
    for (auto& c : connections) shutdown(c.fd, SHUT_RDWR);
    const auto all_done = [&] {
      for (const auto& c : connections)
        if (!c.done) return false;
      return true;
    };
    connection_ended.wait_for(lock, std::chrono::milliseconds(kStopWaitMs), all_done);
    for (auto it = connections.begin(); it != connections.end();) {
      if (it->done) {
        pthread_join(it->thread, nullptr);
        close(it->fd);
        it = connections.erase(it);
      } else {
        ++stuck;
        ++it;
      }
    }
  }
  if (stuck > 0)
    err << "l6470emu serve: " << stuck << (stuck == 1 ? " client is" : " clients are")
        << " still in a message's bus time; stopping without waiting for " << (stuck == 1 ? "it" : "them") << "\n";
  kept.reset();  // the kernel nodes go away before the recordings end
  for (std::size_t i = 0; i < board.chain_count(); ++i) {
    std::string summary;
    if (board.stop_recording(i, &summary)) out << "l6470emu serve: recorded " << summary << "\n";
  }
  if (!config.coverage.empty()) {
    const auto data = board.coverage(stuck > 0);
    const std::string error = data ? merge_into_coverage_file(config.coverage, *data) : "a client still holds the board";
    if (error.empty())
      out << "l6470emu serve: interface coverage merged into " << config.coverage << "\n";
    else
      err << "l6470emu serve: coverage not written: " << error << "\n";
  }
  if (stuck > 0) {
    // Threads still use the board: end the process here rather than destroy it under them.
    out.flush();
    err.flush();
    std::fflush(nullptr);
    _exit(0);
  }
  board.stop_pump();
  if (sfd >= 0) close(sfd);
  return 0;
}

int run_ctl(const std::string& socket_path, const std::string& command, std::ostream& out, std::ostream& err) {
  const std::string where = terminal_safe(socket_path);
  const int s = connect_to(socket_path);
  if (s < 0) {
    err << "l6470emu ctl: no daemon at " << where << " (" << std::strerror(errno) << "); start one with `l6470emu serve`\n";
    return 1;
  }
  // Whoever listens at the path must be us or root before it hears a command or is believed.
  if (const std::string foreign = check_server_owner(s, socket_path); !foreign.empty()) {
    close(s);
    err << "l6470emu ctl: " << terminal_safe(foreign) << "\n";
    return 1;
  }
  RequestHeader req{static_cast<std::uint32_t>(Op::control), static_cast<std::uint32_t>(command.size()), 0, 0};
  std::vector<std::uint8_t> packet(sizeof req + command.size());
  std::memcpy(packet.data(), &req, sizeof req);
  std::memcpy(packet.data() + sizeof req, command.data(), command.size());
  Packet reply;
  int fd = -1;
  // A refused connection has its refusal waiting even when the command could not be sent.
  const bool sent = send_packet(s, packet.data(), packet.size(), {}, -1);
  const int send_errno = errno;
  errno = 0;
  // Unsent for another reason than the daemon's end (too long a command): no answer will come.
  const bool received = (sent || send_errno == EPIPE || send_errno == ECONNRESET) && recv_packet(s, reply, fd, true);
  const int recv_errno = errno;
  close(s);
  if (fd >= 0) close(fd);
  if (!received) {
    const int e = recv_errno ? recv_errno : sent ? 0 : send_errno;
    err << "l6470emu ctl: the daemon at " << where << " did not answer ("
        << (e ? std::strerror(e) : "it closed the connection") << ")\n";
    return 1;
  }
  const CtlOutcome o = decode_ctl_reply(reply.bytes(), socket_path);
  (o.on_stderr ? err : out) << o.text;
  return o.status;
}

}  // namespace l6470emu
