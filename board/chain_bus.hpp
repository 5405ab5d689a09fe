// What a front clocks on: a chain (or its recording) behind its chip-select, as a host with
// given wire settings drives it (SPI mode, bit order, CS polarity: spi/wire.hpp), watched by the
// chain's sanitizer checks. It adds no behaviour of the chips; it is the board's side of the wire.
#pragma once

#include "board/sanitizer.hpp"
#include "daisychain/chain.hpp"
#include "spi/spi_device.hpp"
#include "spi/wire.hpp"

namespace l6470emu {

/// A chain's bus for one front at a time. begin() a use with the host's settings, clock on it
/// through the SpiDevice face (select/exchange/deselect take the settings given to begin();
/// exchange_wire may change speed and word size per transfer), end() it. With CS active high the
/// chain is never selected: bytes reach nothing, MISO reads 0x00, time still passes.
class ChainBus final : public SpiDevice {
 public:
  /// `device` is `chain` or its recording, `checker` the chain's checks; all outlive the bus.
  ChainBus(SpiDevice& device, Chain& chain, ChainChecker& checker) : dev_(&device), chain_(&chain), checker_(&checker) {}

  /// The device the bytes go to (the chain, or its recording while it is recorded).
  void set_device(SpiDevice& device) { dev_ = &device; }
  /// A front whose CS edges carry no time of their own (Python's Chain.frame: time moves only
  /// when told): no t_disCS, neither the chips' missed answer load nor its check.
  void set_untimed() { timed_ = false; }
  /// A use begins: the host drives the bus with `wire`.
  void begin(const WireSettings& wire);
  /// The use ends (the checks of a whole message).
  void end();
  const WireSettings& wire() const { return wire_; }

  // SpiDevice: both faces behave as a host with the settings of begin().
  void select() override { select_wire(); }
  std::uint8_t exchange(std::uint8_t mosi) override;
  void exchange(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) override { exchange_wire(tx, rx, wire_); }
  void deselect() override { deselect_wire(); }
  bool selected() const override { return wire_.cs_active_high ? host_selected_ : chain_->selected(); }
  void select_wire() override;
  void exchange_wire(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx, const WireSettings& wire) override;
  void deselect_wire() override;
  // Time is the chain's (a recording only forwards it).
  Tick now() const override { return chain_->now(); }
  void advance_to(Tick tick) override { chain_->advance_to(tick); }

 private:
  SpiDevice* dev_;
  Chain* chain_;
  ChainChecker* checker_;
  WireSettings wire_;
  bool host_selected_ = false;  // CS active high: the host's CS is asserted (the chain's is not)
  bool timed_ = true;
};

}  // namespace l6470emu
