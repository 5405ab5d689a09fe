// The shared request/reply slot: region layout, sequence numbers, bounded spin, futex sleep/wake.
#include "linux/shm_channel.hpp"

#include <fcntl.h>
#include <linux/futex.h>
#include <poll.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstddef>
#include <cstring>
#include <ctime>

#include "linux/clock.hpp"

namespace l6470emu {

namespace {

// One side's half: the words it writes, then its packet bytes. Each half starts on its own
// cache line so that the two sides never write the same line; the packet starts in the words'
// line, so a small message and its sequence number cross between the cores together.
struct alignas(64) Half {
  std::atomic<std::uint32_t> sequence;  // bumped (client) or copied (daemon) when a packet is posted
  std::atomic<std::uint32_t> size;      // bytes of the packet
  std::atomic<std::uint32_t> flags;     // kShmOnSocket
  std::atomic<std::uint32_t> sleeping;  // 1 while this side waits on the other's futex
  std::uint8_t data[kShmAreaBytes];
};

static_assert(sizeof(std::atomic<std::uint32_t>) == 4 && std::atomic<std::uint32_t>::is_always_lock_free,
              "the futex words must be plain 32-bit words");
constexpr std::size_t kHalfBytes = (sizeof(Half) + 63) / 64 * 64;

Half& client_half(void* base) { return *static_cast<Half*>(base); }
Half& daemon_half(void* base) { return *reinterpret_cast<Half*>(static_cast<std::uint8_t*>(base) + kHalfBytes); }

inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

/// Shared (not private) futexes: the two sides are different processes.
bool futex_wait(std::atomic<std::uint32_t>& word, std::uint32_t expected, int timeout_ms) {
  const timespec t{timeout_ms / 1000, static_cast<long>(timeout_ms % 1000) * 1'000'000};
  const long r = syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&word), FUTEX_WAIT, expected, &t, nullptr, 0);
  return !(r != 0 && errno == ETIMEDOUT);  // false: the timeout ran out
}

void futex_wake(std::atomic<std::uint32_t>& word) {
  syscall(SYS_futex, reinterpret_cast<std::uint32_t*>(&word), FUTEX_WAKE, INT_MAX, nullptr, nullptr, 0);
}

/// How long a waiter polls flat out before it yields the CPU between polls (ns). An answer
/// that comes at all comes within about a microsecond when both sides have a core; when they
/// do not (a loaded machine, or one core), the other side may be queued behind this very
/// spinner, and yielding lets it run. Measured on a loaded 2-core machine: several times the
/// round trips of pure polling.
constexpr std::int64_t kPollNs = 1000;

/// Polls `ready` for up to `spin_ns` (yielding after kPollNs); the clock is read once per 64 polls.
template <typename Ready>
bool spin_until(const Ready& ready, std::int64_t spin_ns) {
  if (ready()) return true;
  if (spin_ns <= 0) return false;
  const std::int64_t start = monotonic_ns();
  for (;;) {
    for (int i = 0; i < 64; ++i) {
      if (ready()) return true;
      cpu_relax();
    }
    const std::int64_t now = monotonic_ns();
    if (now - start >= spin_ns) return false;
    if (now - start >= kPollNs) sched_yield();
  }
}

/// Waits until `done(word)` (the other side posted): spin, then futex sleeps with `sleeping`
/// raised, asking `alive` after each timeout. The Dekker pair — we raise `sleeping` then re-read
/// `word`, the poster writes `word` then reads `sleeping`, all sequentially consistent —
/// guarantees that a post is never missed without a wake-up.
template <typename Done>
bool wait_for(std::atomic<std::uint32_t>& word, const Done& done, std::atomic<std::uint32_t>& sleeping,
              std::int64_t spin_ns, const std::function<bool()>& alive) {
  const auto ready = [&] { return done(word.load(std::memory_order_acquire)); };
  if (spin_until(ready, spin_ns)) return true;
  for (;;) {
    sleeping.store(1, std::memory_order_seq_cst);
    bool woken = true;
    if (const std::uint32_t now = word.load(std::memory_order_seq_cst); !done(now))
      woken = futex_wait(word, now, kShmAliveCheckMs);
    sleeping.store(0, std::memory_order_relaxed);
    if (ready()) return true;
    if (!woken && alive && !alive()) return false;
  }
}

/// Publishes a post: `sequence` first, then a wake-up only if the other side sleeps.
void publish(std::atomic<std::uint32_t>& sequence, std::uint32_t value, std::atomic<std::uint32_t>& other_sleeping) {
  sequence.store(value, std::memory_order_seq_cst);
  if (other_sleeping.load(std::memory_order_seq_cst) != 0) futex_wake(sequence);
}

}  // namespace

std::size_t SharedChannel::region_bytes() {
  static_assert(offsetof(Half, data) == 16 && sizeof(Half) == 64 * 1024, "a half is 64 KiB, its packet after 4 words");
  return 2 * kHalfBytes;
}

SharedChannel::SharedChannel(void* base, std::size_t bytes) : base_(base), bytes_(bytes) {}

SharedChannel::~SharedChannel() {
  if (base_) munmap(base_, bytes_);
}

std::unique_ptr<SharedChannel> SharedChannel::create(int& fd) {
  fd = memfd_create("l6470emu-channel", MFD_CLOEXEC | MFD_ALLOW_SEALING);
  if (fd < 0) return nullptr;
  // Sealed at its size: a client that truncated the file would make the daemon's next access a SIGBUS.
  if (ftruncate(fd, static_cast<off_t>(region_bytes())) != 0 ||
      fcntl(fd, F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_SEAL) != 0) {
    const int e = errno;
    close(fd);
    fd = -1;
    errno = e;
    return nullptr;
  }
  void* base = mmap(nullptr, region_bytes(), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (base == MAP_FAILED) {
    const int e = errno;
    close(fd);
    fd = -1;
    errno = e;
    return nullptr;
  }
  return std::unique_ptr<SharedChannel>(new SharedChannel(base, region_bytes()));
}

std::unique_ptr<SharedChannel> SharedChannel::attach(int fd) {
  struct stat st{};
  if (fstat(fd, &st) != 0 || static_cast<std::size_t>(st.st_size) != region_bytes()) return nullptr;
  void* base = mmap(nullptr, region_bytes(), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (base == MAP_FAILED) return nullptr;
  std::unique_ptr<SharedChannel> c(new SharedChannel(base, region_bytes()));
  // A fresh region is all zeros; carry on from whatever it holds all the same.
  c->sequence_ = client_half(c->base_).sequence.load(std::memory_order_acquire);
  return c;
}

std::uint8_t* SharedChannel::request_area() { return client_half(base_).data; }

void SharedChannel::post_request(std::uint32_t size, std::uint32_t flags) {
  Half& c = client_half(base_);
  c.size.store(size, std::memory_order_relaxed);
  c.flags.store(flags, std::memory_order_relaxed);
  publish(c.sequence, ++sequence_, daemon_half(base_).sleeping);
}

bool SharedChannel::wait_reply(std::int64_t spin_ns, const std::function<bool()>& alive) {
  // The daemon copies the request's sequence number into its half when it replies.
  const std::uint32_t posted = sequence_;
  return wait_for(daemon_half(base_).sequence, [posted](std::uint32_t v) { return v == posted; },
                  client_half(base_).sleeping, spin_ns, alive);
}

std::span<const std::uint8_t> SharedChannel::reply() const {
  const Half& d = daemon_half(base_);
  const std::size_t n = std::min<std::size_t>(d.size.load(std::memory_order_relaxed), kShmAreaBytes);
  return {d.data, n};
}

std::uint32_t SharedChannel::reply_flags() const { return daemon_half(base_).flags.load(std::memory_order_relaxed); }

bool SharedChannel::wait_request(std::int64_t spin_ns, const std::function<bool()>& alive) {
  const std::uint32_t taken = sequence_;
  return wait_for(client_half(base_).sequence, [taken](std::uint32_t v) { return v != taken; },
                  daemon_half(base_).sleeping, spin_ns, alive);
}

std::size_t SharedChannel::take_request(std::uint8_t* out, std::uint32_t& flags) {
  Half& c = client_half(base_);
  sequence_ = c.sequence.load(std::memory_order_acquire);
  flags = c.flags.load(std::memory_order_relaxed);
  // Read once: the client may change it while we copy, but not the bound we copy by.
  const std::size_t n = c.size.load(std::memory_order_relaxed);
  if (n > kShmAreaBytes) return 0;
  std::memcpy(out, c.data, n);
  return n;
}

void SharedChannel::post_reply(std::span<const std::uint8_t> head, std::span<const std::uint8_t> body,
                               std::uint32_t flags) {
  Half& d = daemon_half(base_);
  const std::size_t n = std::min(head.size(), kShmAreaBytes);
  const std::size_t m = std::min(body.size(), kShmAreaBytes - n);
  if (n) std::memcpy(d.data, head.data(), n);
  if (m) std::memcpy(d.data + n, body.data(), m);
  d.size.store(static_cast<std::uint32_t>(n + m), std::memory_order_relaxed);
  d.flags.store(flags, std::memory_order_relaxed);
  publish(d.sequence, sequence_, client_half(base_).sleeping);
}

bool peer_alive(int sock) {
  // The socket's hang-up, not its data: a peer that wrote a packet and died leaves the packet
  // unread, and a peek would find it and answer "alive" for ever. When the peer's end closes (or
  // this end is shut down), the kernel marks the socket hung up whatever is still queued. A raw
  // ppoll: inside the preload library poll() is the library's own replacement.
  pollfd p{sock, static_cast<short>(POLLIN | POLLRDHUP), 0};
  const timespec zero{0, 0};
  for (;;) {
    const long n = syscall(SYS_ppoll, &p, 1, &zero, nullptr, 0);
    if (n >= 0) break;
    if (errno != EINTR) return false;
  }
  return (p.revents & (POLLHUP | POLLRDHUP | POLLERR | POLLNVAL)) == 0;
}

}  // namespace l6470emu
