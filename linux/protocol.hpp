// The wire protocol between the preload library and `l6470emu serve`: one SOCK_SEQPACKET
// connection per host process, strictly request/reply. A request is a RequestHeader and a
// payload; a reply is a ReplyHeader, a payload and, for new files, one descriptor passed
// with SCM_RIGHTS. A packet larger than kInlinePacket travels in a sealed memfd instead
// (packet_memfd.hpp), whatever the socket's buffer. After Op::attach_shm the same packets travel through a region of shared
// memory (shm_channel.hpp) instead, and the socket carries only what the region cannot:
// descriptors and packets larger than its areas. Both ends are built from this one header
// (same machine, same build).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "linux/device_board.hpp"

namespace l6470emu {

class SharedChannel;

/// Protocol version; the daemon refuses a hello of another version.
inline constexpr std::uint32_t kProtocolVersion = 1;

/// What a request asks for.
enum class Op : std::uint32_t {
  hello = 1,        ///< arg = version; reply payload = the catalogue of device nodes
  open = 2,         ///< arg = device index | kOpenCloexec; reply: handle, kind, fd
  closed = 3,       ///< handle: a descriptor of it was closed
  ioctl = 4,        ///< handle, arg = cmd, payload = argument bytes; reply payload = argument bytes
  spi_message = 5,  ///< handle, payload = spi_ioc_transfer[n] then tx data; reply payload = rx data
  spi_read = 6,     ///< handle, arg = count; reply payload = rx data
  spi_write = 7,    ///< handle, payload = tx data
  control = 8,      ///< payload = a ctl command line; reply: exit status and text
  attach_shm = 9,   ///< reply: result = region bytes, the region's memfd (see shm_channel.hpp)
  pwm = 10,         ///< handle = chain, arg = pwm_request_arg(); payload = text written; reply payload = text read
};

/// Op::pwm's arg: the channel (-1: a pwmchip's own file), the attribute, and whether it is a
/// write (DeviceBoard::pwm_write) or a read (DeviceBoard::pwm_read).
inline std::uint64_t pwm_request_arg(int channel, PwmAttr attr, bool write) {
  return static_cast<std::uint32_t>(channel + 1) | std::uint64_t{static_cast<std::uint8_t>(attr)} << 32 |
         std::uint64_t{write} << 40;
}

inline constexpr std::uint64_t kOpenCloexec = std::uint64_t{1} << 63;

struct RequestHeader {
  std::uint32_t op = 0;
  std::uint32_t payload = 0;  ///< bytes following the header
  std::uint64_t handle = 0;
  std::uint64_t arg = 0;
};

struct ReplyHeader {
  std::int64_t result = 0;    ///< >= 0, or -errno
  std::uint32_t payload = 0;  ///< bytes following the header
  std::uint32_t kind = 0;     ///< HandleKind of a new file
  std::uint64_t handle = 0;   ///< handle of a new file (its descriptor rides along with SCM_RIGHTS)
};

/// ReplyHeader::kind of a refusal: the daemon's first and only packet on a connection it will not
/// serve (another user, too many clients), sent at once and followed by the connection's end.
/// result is -ECONNREFUSED and the payload one line saying why (text of the daemon's choosing:
/// clients escape it before printing it).
inline constexpr std::uint32_t kRefusalKind = 0x52454655;  // "REFU"

/// Largest data of a message: bufsiz is at most 4 MiB (config), tx and rx each.
inline constexpr std::size_t kMaxMessage = std::size_t{4} << 20;
/// Most transfers of one SPI_IOC_MESSAGE, as the kernel's spidev takes them: the ioctl's size
/// field is 14 bits, 511 transfers of 32 bytes (so at most 511 x 65.535 ms of delays).
inline constexpr std::size_t kMaxTransfers = 511;
/// Largest packet: a header, 511 transfers (_IOC_SIZE is 14 bits) and the tx data.
inline constexpr std::size_t kMaxPacket = kMaxMessage + 16384 + 64;

/// The catalogue as text ("spidev PATH NAME MAJOR MINOR BUFSIZ" lines) and back.
std::string encode_catalogue(const std::vector<DeviceNode>& nodes);
std::vector<DeviceNode> decode_catalogue(const std::string& text);

/// Sends `header` + `payload` (+ `fd` if >= 0) as one packet. Returns false on error (errno set).
/// A packet of at most kInlinePacket bytes is one datagram, as it always was; a larger one (or
/// one the socket's buffer refuses with EMSGSIZE) travels in a sealed memfd under a
/// BigPacketEnvelope (packet_memfd.hpp), the memfd first in its SCM_RIGHTS message and `fd`
/// second. EMSGSIZE for a packet larger than kMaxPacket.
bool send_packet(int sock, const void* header, std::size_t header_size, std::span<const std::uint8_t> payload, int fd);
/// A receive buffer as large as the largest packet (allocated, not touched: pages are used on demand).
struct Packet {
  std::unique_ptr<std::uint8_t[]> data{new std::uint8_t[kMaxPacket]};
  std::size_t size = 0;
  std::span<const std::uint8_t> bytes() const { return {data.get(), size}; }
};

/// The packet that refuses a connection (kRefusalKind), saying `why`.
std::vector<std::uint8_t> encode_refusal(const std::string& why);
/// When `packet` is a refusal: its reason, at most 512 bytes of it (else nullopt).
std::optional<std::string> decode_refusal(std::span<const std::uint8_t> packet);

/// Whether the server at the other end of the connected socket `sock` may be trusted: it runs as
/// this process's effective user or as root (SO_PEERCRED, as the kernel recorded it when the
/// server listened). "" when it may, else one line saying whose it is.
std::string check_server_owner(int sock, const std::string& path);

/// Receives one packet; `fd` gets a passed descriptor or -1 (`cloexec` sets close-on-exec on it).
/// A big packet (BigPacketEnvelope) is read from its memfd into `packet`, the memfd closed; one
/// whose memfd is missing, not a sealed memfd, of another size than its envelope says or larger
/// than kMaxPacket is refused: false with errno EPROTO, every descriptor that came with it closed.
/// Descriptors beyond the packet's one (and the memfd) are always closed.
/// Polls without sleeping for up to `spin_ns` first. Returns false on EOF or error. A packet the
/// peer sent before it closed the connection is still received (a refusal), even when the kernel
/// reports the reset first.
bool recv_packet(int sock, Packet& packet, int& fd, bool cloexec, std::int64_t spin_ns = 0);

/// How long the preload polls for a reply, and the daemon for a client's next request, before
/// sleeping (in recvmsg on the socket, or on the shared region's futex).
inline constexpr std::int64_t kReplySpinNs = 30'000;
inline constexpr std::int64_t kRequestSpinNs = 20'000;

/// A control command handler: text in, exit status and text out (the daemon's `ctl`).
using ControlHandler = std::function<int(const std::string& command, std::string& output)>;

/// Serves one request on `board` (the daemon side). Fills `reply` and its payload;
/// `pass_fd` gets a descriptor to send along (the caller closes its copy after sending).
/// `client_alive` says whether the client is still there: a long SPI message of a client that
/// died is given up midway (DeviceBoard::spi_message), so that no one waits out its bus time.
void serve_request(DeviceBoard& board, const ControlHandler& control, std::span<const std::uint8_t> packet,
                   ReplyHeader& reply, std::vector<std::uint8_t>& reply_payload, int& pass_fd,
                   const std::function<bool()>& client_alive = {});

/// What serve_shared_request did with the request posted in a shared channel.
enum class SharedOutcome {
  replied,            ///< the reply is in the region
  reply_on_socket,    ///< the reply carries a descriptor or does not fit: the caller sends `reply`,
                      ///< `reply_payload` and `pass_fd` on the socket, then posts kShmOnSocket
  request_on_socket,  ///< the client sent its packet on the socket: the caller receives and serves it
};

/// Serves the request posted in `channel` (the daemon side) exactly as serve_request serves it
/// from the socket. The region is the client's to scribble on, so the request is first copied
/// into `scratch` (kShmAreaBytes), its size checked against the area.
SharedOutcome serve_shared_request(DeviceBoard& board, const ControlHandler& control, SharedChannel& channel,
                                   std::uint8_t* scratch, ReplyHeader& reply, std::vector<std::uint8_t>& reply_payload,
                                   int& pass_fd, const std::function<bool()>& client_alive = {});

}  // namespace l6470emu
