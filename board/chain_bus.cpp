// ChainBus: the host's settings and CS polarity between a front and a chain, and the calls to
// the chain's checks around each edge.
#include "board/chain_bus.hpp"

#include <algorithm>

namespace l6470emu {

void ChainBus::begin(const WireSettings& wire) {
  wire_ = wire;
  checker_->begin_use(wire);
}

void ChainBus::end() { checker_->end_use(); }

void ChainBus::select_wire() {
  if (wire_.cs_active_high) {
    // The host asserts CS high: the chip's active-low CS is driven away from select. Nothing of
    // the frame reaches the chain, so only the setting itself is reported (begin_use).
    host_selected_ = true;
    return;
  }
  if (chain_->selected()) return;
  if (timed_)
    dev_ == chain_ ? chain_->select_wire() : dev_->select_wire();
  else
    dev_->select();
  checker_->selected(chain_->now(), timed_);
}

std::uint8_t ChainBus::exchange(std::uint8_t mosi) {
  std::uint8_t miso = 0;
  exchange_wire(std::span<const std::uint8_t>(&mosi, 1), std::span<std::uint8_t>(&miso, 1), wire_);
  return miso;
}

void ChainBus::exchange_wire(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx, const WireSettings& wire) {
  if (wire_.cs_active_high) {
    std::fill(rx.begin(), rx.begin() + static_cast<std::ptrdiff_t>(tx.size()), std::uint8_t{0});
    return;
  }
  checker_->clocked(tx, wire, chain_->now());  // (nothing while CS is high)
  if (dev_ == chain_)
    chain_->exchange_wire(tx, rx, wire);  // (a direct call: Chain is final)
  else
    dev_->exchange_wire(tx, rx, wire);
}

void ChainBus::deselect_wire() {
  if (wire_.cs_active_high) {
    host_selected_ = false;
    return;
  }
  if (!chain_->selected()) return;
  checker_->deselecting();
  dev_ == chain_ ? chain_->deselect_wire() : dev_->deselect_wire();
  checker_->deselected(chain_->now());
}

}  // namespace l6470emu
