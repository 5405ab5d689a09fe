// Packets too large for one SOCK_SEQPACKET datagram. The kernel refuses a datagram larger than
// the socket's send buffer (wmem_default, about 208 KiB) with EMSGSIZE, and raising the buffer
// past wmem_max needs CAP_NET_ADMIN; a packet larger than kInlinePacket (requests and replies of
// SPI messages up to kMaxPacket) therefore travels as a sealed memfd holding the whole packet,
// passed with SCM_RIGHTS under a small BigPacketEnvelope that says how many bytes it holds.
// send_packet and recv_packet (protocol.hpp) use these; their callers never see the envelope.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace l6470emu {

/// Largest packet sent inline, as one datagram; larger ones go in a memfd. Well under the
/// default socket buffer (212 992 bytes), so that no usual configuration makes it fail.
inline constexpr std::size_t kInlinePacket = std::size_t{128} << 10;

/// BigPacketEnvelope::magic ("BIGP").
inline constexpr std::uint32_t kBigPacketMagic = 0x50474942;

/// The datagram that stands for a packet in a memfd. It is 16 bytes, shorter than any header
/// (RequestHeader and ReplyHeader are 24), so no ordinary packet is ever taken for one. Its
/// SCM_RIGHTS message holds the memfd first and then, if the packet has one, the packet's own
/// descriptor (a new file's, ReplyHeader::handle).
struct BigPacketEnvelope {
  std::uint32_t magic = kBigPacketMagic;
  std::uint32_t reserved = 0;  ///< 0
  std::uint64_t size = 0;      ///< bytes in the memfd: the whole packet, header included
};
static_assert(sizeof(BigPacketEnvelope) == 16);

/// A new memfd holding `header` then `payload`, sealed against writing, growing and shrinking
/// (F_SEAL_SEAL too), close-on-exec. -1 on error (errno set).
int seal_packet(const void* header, std::size_t header_size, std::span<const std::uint8_t> payload);

/// Reads the packet of `size` bytes held by `fd` into `into` (room for kMaxPacket bytes), after
/// checking that `fd` is a memfd sealed against writing, growing and shrinking, that it holds
/// exactly `size` bytes and that `size` is at most kMaxPacket; so a peer can neither make us read
/// more than a packet nor change it while we read, and the read never blocks. False with errno
/// EPROTO when the descriptor is not such a memfd or its size differs. Does not close `fd`.
bool load_packet(int fd, std::uint64_t size, std::uint8_t* into);

}  // namespace l6470emu
