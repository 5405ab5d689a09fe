// A request/reply slot in memory shared by one preload client process and `l6470emu serve`:
// the protocol's packets (protocol.hpp) carried without a system call while both sides are
// awake, with futex wake-ups when one of them sleeps. Not here: what a packet means
// (protocol.hpp) and who serves which connection (serve/daemon.cpp).
//
// The region (a memfd the daemon makes and passes with SCM_RIGHTS) has two halves, each written
// by one side only: the client's (request sequence number, size, flags, "I sleep" word, request
// bytes) and the daemon's (the same for the reply). One request is outstanding at a time, as on
// the socket. The daemon treats the client's half as hostile input: it reads the size once,
// checks it against the area and copies the request out before parsing it.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>

namespace l6470emu {

/// Bytes of the request area and of the reply area each. A packet that does not fit goes by the
/// socket instead (kShmOnSocket), so this bounds only what travels without a system call.
inline constexpr std::size_t kShmAreaBytes = 64 * 1024 - 16;

/// Request flag: "my packet is on the socket" (it carries what the region cannot: a descriptor,
/// more than kShmAreaBytes). Reply flag: "your reply is on the socket".
inline constexpr std::uint32_t kShmOnSocket = 1;

/// How long a side sleeps on the futex before it asks whether its peer is still there (ms).
inline constexpr int kShmAliveCheckMs = 200;

/// One side's view of a shared region. Move-only; unmaps on destruction.
class SharedChannel {
 public:
  /// The daemon's side: a new region; `fd` gets its descriptor to pass to the client (the caller
  /// closes it). nullptr (errno set) when no memfd can be made.
  static std::unique_ptr<SharedChannel> create(int& fd);
  /// The client's side: maps the region behind `fd` (which the caller may close afterwards).
  /// nullptr when `fd` is not a region of the expected size.
  static std::unique_ptr<SharedChannel> attach(int fd);
  ~SharedChannel();
  SharedChannel(const SharedChannel&) = delete;
  SharedChannel& operator=(const SharedChannel&) = delete;

  // ---- the client -----------------------------------------------------------------------

  /// Where the client writes its request packet (kShmAreaBytes).
  std::uint8_t* request_area();
  /// Publishes the `size` bytes written to request_area() (or, with kShmOnSocket and size 0,
  /// says the packet went by the socket), and wakes the daemon if it sleeps.
  void post_request(std::uint32_t size, std::uint32_t flags);
  /// Waits for the reply to the last posted request: polls for up to `spin_ns`, then sleeps on
  /// the futex, asking `alive()` every kShmAliveCheckMs. False when alive() says no.
  bool wait_reply(std::int64_t spin_ns, const std::function<bool()>& alive);
  /// The reply packet (its size clamped to the area) and its flags.
  std::span<const std::uint8_t> reply() const;
  std::uint32_t reply_flags() const;

  // ---- the daemon -----------------------------------------------------------------------

  /// Waits for the client's next request, as wait_reply waits. False when alive() says no.
  bool wait_request(std::int64_t spin_ns, const std::function<bool()>& alive);
  /// Copies the request just posted into `out` (at least kShmAreaBytes long) and returns its
  /// size; a size beyond the area comes back as 0 (an empty packet, refused by the dispatcher).
  std::size_t take_request(std::uint8_t* out, std::uint32_t& flags);
  /// Whether a reply of `bytes` fits the reply area.
  static bool reply_fits(std::size_t bytes) { return bytes <= kShmAreaBytes; }
  /// Writes the reply (`head` then `body`, which together must fit) with `flags` and wakes the client.
  void post_reply(std::span<const std::uint8_t> head, std::span<const std::uint8_t> body, std::uint32_t flags);

  /// Bytes of the whole region.
  static std::size_t region_bytes();

 private:
  SharedChannel(void* base, std::size_t bytes);

  void* base_ = nullptr;
  std::size_t bytes_ = 0;
  std::uint32_t sequence_ = 0;  // client: the last posted request; daemon: the last one taken
};

/// Whether the other end of `sock` is still there (no hang-up, no error), without waiting: false
/// once the peer closed its end (died), even with its last packets still unread, and once this
/// end was shut down.
bool peer_alive(int sock);

}  // namespace l6470emu
