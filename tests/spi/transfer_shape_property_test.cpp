// Property test of DESIGN.md invariant 1, "byte-exact, however the bytes are grouped": one random
// host byte stream, cut into CS frames, delivered as spidev messages of random shapes (several
// frames per message via cs_change, frames split into 1-byte or random transfers, frames continued
// across messages with cs_change on the last transfer, empty transfers, rx-only and tx-only
// transfers) must give the same MISO bytes and the same final chip state as plain delivery with
// one message per frame.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "daisychain/chain.hpp"
#include "spi/message.hpp"

namespace l6470emu {
namespace {

using Bytes = std::vector<std::uint8_t>;
using Rng = std::mt19937;

/// One CS frame of the host stream: its bytes, the SCK speed and the delay before CS rises.
struct Frame {
  Bytes tx;
  std::uint32_t speed_hz = 0;
  std::uint16_t delay_usecs = 0;
};

unsigned pick(Rng& rng, unsigned lo, unsigned hi) { return std::uniform_int_distribution<unsigned>(lo, hi)(rng); }
bool chance(Rng& rng, double p) { return std::bernoulli_distribution(p)(rng); }

void push_value(Bytes& out, std::uint32_t v, unsigned bytes) {
  for (unsigned i = bytes; i-- > 0;) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

/// One random command of a careful host (answers are read with NOPs), as bytes for one chip.
void random_command(Rng& rng, Bytes& out) {
  const Variant& v = l6470();
  const unsigned r = pick(rng, 0, 99);
  if (r < 22) {  // SetParam of a writable register (WS/WH writes may well be refused)
    const RegisterInfo* reg;
    do reg = &v.registers[pick(rng, 0, static_cast<unsigned>(v.registers.size()) - 1)];
    while (reg->access == Access::R);
    out.push_back(reg->address);
    std::uint32_t value = pick(rng, 0, 0xFFFFFF);
    if (reg->id == Reg::ACC || reg->id == Reg::DEC) value = chance(rng, 0.3) ? 0xFFF : pick(rng, 1, 0x400);
    if (reg->id == Reg::MAX_SPEED) value = pick(rng, 0x10, 0x3FF);
    push_value(out, value, reg->spi_bytes());
  } else if (r < 37) {  // GetParam of an existing register, answer read back
    const RegisterInfo& reg = v.registers[pick(rng, 0, static_cast<unsigned>(v.registers.size()) - 1)];
    out.push_back(static_cast<std::uint8_t>(0x20 | reg.address));
    out.insert(out.end(), reg.spi_bytes(), 0x00);
  } else if (r < 47) {  // GetStatus
    out.insert(out.end(), {0xD0, 0x00, 0x00});
  } else if (r < 57) {  // Run
    out.push_back(static_cast<std::uint8_t>(0x50 | pick(rng, 0, 1)));
    push_value(out, pick(rng, 0, 0xFFFFFF), 3);
  } else if (r < 64) {  // Move
    out.push_back(static_cast<std::uint8_t>(0x40 | pick(rng, 0, 1)));
    push_value(out, chance(rng, 0.8) ? pick(rng, 0, 5000) : pick(rng, 0, 0xFFFFFF), 3);
  } else if (r < 68) {  // GoTo / GoTo_DIR
    const std::uint8_t ops[] = {0x60, 0x68, 0x69};
    out.push_back(ops[pick(rng, 0, 2)]);
    push_value(out, pick(rng, 0, 0xFFFFFF), 3);
  } else if (r < 80) {  // stops
    const std::uint8_t ops[] = {0xB0, 0xB8, 0xA0, 0xA8};
    out.push_back(ops[pick(rng, 0, 3)]);
  } else if (r < 84) {
    const std::uint8_t ops[] = {0xD8, 0x70, 0x78, 0x58, 0x59};  // ResetPos GoHome GoMark StepClock
    out.push_back(ops[pick(rng, 0, 4)]);
  } else if (r < 87) {  // GoUntil / ReleaseSW
    const std::uint8_t ops[] = {0x82, 0x83, 0x8A, 0x8B};
    if (chance(rng, 0.5)) {
      out.push_back(ops[pick(rng, 0, 3)]);
      push_value(out, pick(rng, 0, 0xFFFFF), 3);
    } else {
      out.push_back(static_cast<std::uint8_t>(ops[pick(rng, 0, 3)] + 0x10));
    }
  } else if (r < 89) {
    out.push_back(0xC0);  // ResetDevice
  } else if (r < 92) {
    const std::uint8_t wrong[] = {0xEB, 0xF8, 0x52, 0x61, 0xFF, 0x3A, 0x1B};
    out.push_back(wrong[pick(rng, 0, 6)]);
  } else {
    out.push_back(0x00);
  }
}

/// A stream of `frames` N-byte frames: chip k's slot carries its own command sequence.
std::vector<Frame> random_stream(Rng& rng, std::size_t n, std::size_t frames) {
  std::vector<Bytes> per_chip(n);
  for (auto& seq : per_chip)
    while (seq.size() < frames) random_command(rng, seq);
  const std::uint32_t speeds[] = {5'000'000, 4'000'000, 1'000'000, 2'500'000, 3'333'333};
  std::vector<Frame> out(frames);
  for (std::size_t f = 0; f < frames; ++f) {
    for (std::size_t k = 0; k < n; ++k) out[f].tx.push_back(per_chip[k][f]);
    out[f].speed_hz = speeds[pick(rng, 0, 4)];
    const unsigned d = pick(rng, 0, 9);
    out[f].delay_usecs = static_cast<std::uint16_t>(d < 6 ? 0 : d < 9 ? pick(rng, 1, 50) : pick(rng, 500, 5000));
  }
  return out;
}

/// A stream of arbitrary bytes in frames of arbitrary length (1..2N): still a shift register.
std::vector<Frame> random_garbage(Rng& rng, std::size_t n, std::size_t frames) {
  std::vector<Frame> out(frames);
  for (auto& f : out) {
    const unsigned len = pick(rng, 1, static_cast<unsigned>(2 * n));
    for (unsigned i = 0; i < len; ++i) f.tx.push_back(static_cast<std::uint8_t>(pick(rng, 0, 255)));
    f.speed_hz = 5'000'000;
    f.delay_usecs = static_cast<std::uint16_t>(chance(rng, 0.2) ? pick(rng, 1, 2000) : 0);
  }
  return out;
}

// ---------------------------------------------------------------- delivery

/// One planned transfer: a piece of frame `frame` from byte `from`, `len` bytes.
struct Piece {
  std::size_t frame = 0;
  std::size_t from = 0;
  std::size_t len = 0;
  bool ends_frame = false;
  bool tx_only = false;
  bool rx_only = false;
};

/// Result of a delivery: the MISO bytes per frame, and which of them were captured.
struct Delivery {
  std::vector<Bytes> rx;
  std::vector<std::vector<bool>> captured;
};

SpiTransfer make_transfer(const std::vector<Frame>& frames, Delivery& d, const Piece& p) {
  SpiTransfer t;
  const Frame& f = frames[p.frame];
  t.len = static_cast<std::uint32_t>(p.len);
  t.speed_hz = f.speed_hz;
  if (p.len > 0) {
    if (!p.rx_only) t.tx = std::span<const std::uint8_t>(f.tx).subspan(p.from, p.len);
    if (!p.tx_only) t.rx = std::span<std::uint8_t>(d.rx[p.frame]).subspan(p.from, p.len);
    for (std::size_t i = 0; i < p.len; ++i) d.captured[p.frame][p.from + i] = !p.tx_only;
  }
  if (p.ends_frame) t.delay_usecs = f.delay_usecs;
  return t;
}

Delivery empty_delivery(const std::vector<Frame>& frames) {
  Delivery d;
  for (const auto& f : frames) {
    d.rx.emplace_back(f.tx.size(), 0xEE);
    d.captured.emplace_back(f.tx.size(), true);
  }
  return d;
}

/// The reference: one message per frame, one transfer per message.
Delivery deliver_plain(SpiDevice& dev, const std::vector<Frame>& frames) {
  Delivery d = empty_delivery(frames);
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const SpiTransfer t = make_transfer(frames, d, {f, 0, frames[f].tx.size(), true});
    run_message(dev, std::span<const SpiTransfer>(&t, 1));
  }
  return d;
}

/// How to cut a stream: probabilities of a transfer boundary inside a frame and of a message
/// boundary at a transfer boundary, and of the optional decorations.
struct Shape {
  double split_frame = 0;  // cut between two bytes of a frame
  double new_message = 1;  // start a new message at a transfer boundary
  double empty_transfer = 0;
  double rx_only_zeros = 0;  // send an all-zero piece as an rx-only transfer
  double tx_only = 0;
  std::string name;
};

Shape random_shape(Rng& rng) {
  switch (pick(rng, 0, 5)) {
    case 0: return {0, 1, 0, 0, 0, "one message per frame"};
    case 1: return {0, 0.3, 0, 0, 0, "several frames per message (cs_change)"};
    case 2: return {1, 0, 0, 0, 0, "one message of 1-byte transfers"};
    case 3: return {1, 0.5, 0, 0.5, 0, "1-byte transfers, messages cut anywhere, rx-only zeros"};
    case 4: return {0.4, 0.3, 0.1, 0.3, 0.1, "random pieces, messages cut anywhere, empty and tx-only"};
    default: return {0, 0, 0, 0, 0, "all frames in one message"};
  }
}

/// Cuts the stream into pieces and messages as `shape` says and delivers it.
Delivery deliver_shaped(SpiDevice& dev, const std::vector<Frame>& frames, const Shape& shape, Rng& rng) {
  Delivery d = empty_delivery(frames);
  std::vector<Piece> pieces;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const std::size_t len = frames[f].tx.size();
    std::size_t from = 0;
    for (std::size_t i = 1; i <= len; ++i) {
      if (i < len && !chance(rng, shape.split_frame)) continue;
      Piece p{f, from, i - from, i == len};
      bool zeros = true;
      for (std::size_t b = from; b < i; ++b) zeros = zeros && frames[f].tx[b] == 0;
      p.rx_only = zeros && chance(rng, shape.rx_only_zeros);
      p.tx_only = !p.rx_only && chance(rng, shape.tx_only);
      pieces.push_back(p);
      from = i;
    }
  }
  std::vector<SpiTransfer> message;
  auto flush = [&](bool cs_stays_low) {
    if (message.empty()) return;
    message.back().cs_change = cs_stays_low;
    run_message(dev, message);
    message.clear();
  };
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const Piece& p = pieces[i];
    if (!message.empty() && chance(rng, shape.empty_transfer)) {
      SpiTransfer empty;  // len 0, no cs_change: nothing happens in the middle of a message
      message.push_back(empty);
    }
    SpiTransfer t = make_transfer(frames, d, p);
    t.cs_change = p.ends_frame;  // in the middle of a message: raise CS at the end of a frame
    message.push_back(t);
    const bool last = i + 1 == pieces.size();
    if (last || chance(rng, shape.new_message)) {
      // At the end of a message cs_change means the opposite: keep CS low (frame not finished).
      flush(!p.ends_frame);
    }
  }
  return d;
}

// ---------------------------------------------------------------- comparison

std::string describe(const std::vector<Frame>& frames) {
  std::ostringstream s;
  s << std::hex;
  for (const auto& f : frames) {
    s << '[';
    for (auto b : f.tx) s << ' ' << unsigned(b);
    s << " ]";
    if (f.delay_usecs) s << std::dec << '+' << f.delay_usecs << "us" << std::hex;
  }
  return s.str();
}

/// Same MISO (where captured) and same state of every chip. Returns false on the first difference.
bool same_result(const Chain& a, const Delivery& da, const Chain& b, const Delivery& db, std::string& why) {
  for (std::size_t f = 0; f < da.rx.size(); ++f)
    for (std::size_t i = 0; i < da.rx[f].size(); ++i)
      if (db.captured[f][i] && da.rx[f][i] != db.rx[f][i]) {
        why = "MISO differs in frame " + std::to_string(f) + " byte " + std::to_string(i);
        return false;
      }
  if (a.now() != b.now()) {
    why = "time differs: " + std::to_string(a.now()) + " vs " + std::to_string(b.now());
    return false;
  }
  if (a.selected() || b.selected()) {
    why = "CS left low";
    return false;
  }
  for (std::size_t k = 0; k < a.size(); ++k) {
    const Chip& x = a.chip(k);
    const Chip& y = b.chip(k);
    for (const RegisterInfo& r : x.variant().registers)
      if (x.peek(r.id) != y.peek(r.id)) {
        why = "chip " + std::to_string(k) + " register " + std::string(r.name) + " differs";
        return false;
      }
    if (x.status() != y.status()) {
      why = "chip " + std::to_string(k) + " status differs";
      return false;
    }
    if (!(x.motion() == y.motion()) || x.hiz() != y.hiz() || x.now() != y.now()) {
      why = "chip " + std::to_string(k) + " motion state differs";
      return false;
    }
  }
  return true;
}

void check_streams(std::size_t n, std::uint32_t seed, int streams, int shapes_per_stream, bool garbage) {
  Rng rng(seed);
  int failures = 0;
  int moved = 0;          // streams after which some chip is off HOME (the motion was exercised)
  int answered = 0;       // streams whose MISO carried a non-zero byte (answers were exercised)
  for (int s = 0; s < streams && failures < 3; ++s) {
    const std::size_t frame_count = pick(rng, 10, 60);
    const auto frames = garbage ? random_garbage(rng, n, frame_count) : random_stream(rng, n, frame_count);
    Chain plain(n);
    const Delivery reference = deliver_plain(plain, frames);
    bool off_home = false;
    for (std::size_t k = 0; k < n; ++k) off_home = off_home || plain.chip(k).position() != 0;
    moved += off_home;
    bool nonzero = false;
    for (const auto& f : reference.rx)
      for (auto b : f) nonzero = nonzero || b != 0;
    answered += nonzero;
    for (int k = 0; k < shapes_per_stream; ++k) {
      const Shape shape = random_shape(rng);
      Chain shaped(n);
      const Delivery got = deliver_shaped(shaped, frames, shape, rng);
      std::string why;
      if (!same_result(plain, reference, shaped, got, why)) {
        ++failures;
        ADD_FAILURE() << "seed " << seed << " stream " << s << " shape '" << shape.name << "': " << why
                      << "\nstream: " << describe(frames);
        break;
      }
    }
  }
  // Guard against a degenerate generator: the property must be exercised on real traffic.
  EXPECT_GT(moved, streams / 4) << "too few streams moved a motor";
  EXPECT_GT(answered, streams / 2) << "too few streams produced answers";
}

TEST(TransferShapes, GiveTheSameMisoAndStateAsOneMessagePerFrameForOneChip) {
  check_streams(1, 0x6470, 200, 3, false);
}

TEST(TransferShapes, GiveTheSameMisoAndStateAsOneMessagePerFrameForThreeChips) {
  check_streams(3, 0x6471, 200, 3, false);
}

TEST(TransferShapes, GiveTheSameResultForArbitraryBytesInFramesOfAnyLength) {
  check_streams(3, 0x6472, 60, 3, true);
  check_streams(1, 0x6473, 40, 3, true);
}

TEST(TransferShapes, BlockExchangeAndByteByByteExchangeAgreeEvenWithChipsInStandby) {
  // Chain::frame clocks a whole span at once; select/exchange(byte)/deselect one byte at a time.
  Rng rng(0x6474);
  for (int s = 0; s < 150; ++s) {
    const std::size_t n = pick(rng, 1, 5);
    const auto frames = chance(rng, 0.5) ? random_garbage(rng, n, 30) : random_stream(rng, n, 30);
    Chain a(n), b(n);
    for (std::size_t f = 0; f < frames.size(); ++f) {
      if (chance(rng, 0.05)) {  // move a STBY pin between frames, the same on both chains
        const std::size_t k = pick(rng, 0, static_cast<unsigned>(n) - 1);
        const bool level = !a.chip(k).spi_enabled();
        a.chip(k).set_stby_rst_pin(level);
        b.chip(k).set_stby_rst_pin(level);
      }
      const Bytes block = a.frame(frames[f].tx);
      b.select();
      Bytes bytewise;
      for (auto byte : frames[f].tx) bytewise.push_back(b.exchange(byte));
      b.deselect();
      ASSERT_EQ(block, bytewise) << "stream " << s << " frame " << f;
    }
    for (std::size_t k = 0; k < n; ++k) {
      ASSERT_EQ(a.chip(k).status(), b.chip(k).status()) << "stream " << s << " chip " << k;
      for (const RegisterInfo& r : a.chip(k).variant().registers)
        ASSERT_EQ(a.chip(k).peek(r.id), b.chip(k).peek(r.id)) << "stream " << s << " " << r.name;
    }
  }
}

TEST(TransferShapes, ThePlainDeliveryItselfIsDeterministic) {
  Rng rng(7);
  const auto frames = random_stream(rng, 3, 50);
  Chain a(3), b(3);
  const Delivery da = deliver_plain(a, frames);
  const Delivery db = deliver_plain(b, frames);
  std::string why;
  EXPECT_TRUE(same_result(a, da, b, db, why)) << why;
}

}  // namespace
}  // namespace l6470emu
