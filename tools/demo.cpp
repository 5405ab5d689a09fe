// Demo: each chip of a chain gets its own Move through one spidev message per
// command; the host polls GetStatus and ABS_POS every 100 ms of virtual time.
#include "tools/demo.hpp"

#include <cstdio>
#include <string>
#include <vector>

#include "core/status.hpp"
#include "daisychain/chain.hpp"
#include "spi/message.hpp"

namespace l6470emu {
namespace {

/// Sends the same-length command `per_chip[k]` to every chip k in one spidev message:
/// one transfer per byte position with cs_change, as a daisy-chain driver does.
std::vector<std::vector<std::uint8_t>> chain_command(Chain& chain, const std::vector<std::vector<std::uint8_t>>& per_chip) {
  const std::size_t n = chain.size();
  const std::size_t len = per_chip[0].size();
  std::vector<std::vector<std::uint8_t>> tx(len, std::vector<std::uint8_t>(n)), rx = tx;
  std::vector<SpiTransfer> transfers;
  for (std::size_t f = 0; f < len; ++f) {
    for (std::size_t k = 0; k < n; ++k) tx[f][k] = per_chip[k][f];
    transfers.push_back({tx[f], rx[f], static_cast<std::uint32_t>(n), 4'000'000, 0, f + 1 < len});
  }
  run_message(chain, transfers);
  return rx;
}

std::vector<std::vector<std::uint8_t>> same_for_all(std::size_t n, std::vector<std::uint8_t> cmd) {
  return std::vector<std::vector<std::uint8_t>>(n, std::move(cmd));
}

}  // namespace

int run_demo(std::size_t chips, unsigned seconds, std::ostream& out) {
  Chain chain(chips);
  const std::size_t n = chain.size();
  out << "l6470emu demo: " << n << " x L6470 in one daisy chain, SPI at 4 MHz, spidev message semantics\n";

  // Clear the power-up UVLO flag, then give chip k a Move of (k+1) * 10000 microsteps.
  chain_command(chain, same_for_all(n, {0xD0, 0x00, 0x00}));
  std::vector<std::vector<std::uint8_t>> moves;
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t steps = static_cast<std::uint32_t>((k + 1) * 10000);
    moves.push_back({static_cast<std::uint8_t>(0x40 | (k % 2 == 0)), static_cast<std::uint8_t>(steps >> 16),
                     static_cast<std::uint8_t>(steps >> 8), static_cast<std::uint8_t>(steps)});
  }
  chain_command(chain, moves);
  out << "sent Move(FWD/REV, (k+1)*10000 microsteps) to every chip k\n\n";

  for (unsigned tenth = 1; tenth <= seconds * 10; ++tenth) {
    chain.advance_to(ticks_from_ms(100) * tenth);
    const auto st = chain_command(chain, same_for_all(n, {0xD0, 0x00, 0x00}));
    const auto pos = chain_command(chain, same_for_all(n, {0x21, 0x00, 0x00, 0x00}));
    char head[32];
    std::snprintf(head, sizeof head, "t=%5.2f s", tenth / 10.0);
    out << head;
    bool any_busy = false;
    for (std::size_t k = 0; k < n; ++k) {
      const std::uint16_t status = static_cast<std::uint16_t>(st[1][k] << 8 | st[2][k]);
      const std::int32_t p = sign_extend(static_cast<std::uint32_t>(pos[1][k] << 16 | pos[2][k] << 8 | pos[3][k]), 22);
      char cell[64];
      std::snprintf(cell, sizeof cell, " | chip %zu: ABS_POS %7d STATUS 0x%04X", k, p, status);
      out << cell;
      any_busy = any_busy || (status & 0x0002) == 0;
    }
    out << '\n';
    if (!any_busy) break;
  }
  out << '\n';
  for (std::size_t k = 0; k < n; ++k)
    out << "chip " << k << ": " << describe_status(chain.chip(k).status_layout(), chain.chip(k).status()) << '\n';
  return 0;
}

}  // namespace l6470emu
