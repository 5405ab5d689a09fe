// SPIClass over the FirmwareRuntime: a controller found by name on first use, the transaction's
// settings turned into the board's bus settings, each call one HAL call plus its bytes' bus time.
// The model first: Arduino.h's macros (HIGH, DEC, ...) must not reach its headers.
#include "firmware/arduino/arduino_internal.hpp"

#include "SPI.h"

#include <algorithm>
#include <string>
#include <vector>


using l6470emu::arduino::runtime;

SPIClass SPI;
SPIClass SPI1(static_cast<uint8_t>(0xF1));
SPIClass SPI2(static_cast<uint8_t>(0xF2));

namespace {

const char* esp32_bus_name(uint8_t bus) {
  switch (bus) {
    case FSPI: return "FSPI";
    case HSPI: return "HSPI";
    case VSPI: return "VSPI";
    case 0xF1: return "SPI1";
    case 0xF2: return "SPI2";
    default: return "SPI";
  }
}

// The controller an STM32F4 routes MOSI pin `mosi` to by default (Arduino pin numbers: PA0 = 128).
const char* stm32_bus_of_mosi(uint32_t mosi) {
  auto pin = [](char port, unsigned n) { return 128u + static_cast<unsigned>(port - 'A') * 16 + n; };
  if (mosi == pin('A', 7) || mosi == pin('B', 5)) return "SPI1";
  if (mosi == pin('B', 15) || mosi == pin('C', 3)) return "SPI2";
  if (mosi == pin('C', 12)) return "SPI3";
  if (mosi == pin('E', 6) || mosi == pin('E', 14)) return "SPI4";
  return "SPI";
}

// SPI_MODE0..3 as the AVR core writes them (0x00, 0x04, 0x08, 0x0C) or as mode numbers 0..3.
uint8_t mode_number(uint8_t data_mode) { return data_mode <= 3 ? data_mode : static_cast<uint8_t>((data_mode >> 2) & 3); }

uint32_t divider_clock(uint8_t div) {
  static const uint32_t dividers[] = {4, 16, 64, 128, 2, 8, 32, 64};
  return static_cast<uint32_t>(F_CPU / dividers[div & 7]);
}

}  // namespace

SPIClass::SPIClass() : name_("SPI") {}
SPIClass::SPIClass(uint8_t spi_bus) : name_(esp32_bus_name(spi_bus)) {}
SPIClass::SPIClass(uint32_t mosi, uint32_t, uint32_t, uint32_t) : name_(stm32_bus_of_mosi(mosi)) {}

void SPIClass::begin(int8_t, int8_t, int8_t, int8_t) {
  runtime().call();
  begun_ = true;
}

void SPIClass::end() {
  runtime().call();
  begun_ = false;
}

void SPIClass::beginTransaction(SPISettings settings) {
  l6470emu::FirmwareRuntime& r = runtime();
  r.call();
  settings_ = settings;
  in_transaction_ = true;
  for (const int n : masked_)
    if (const int irq = l6470emu::arduino::irq_of_interrupt(n); n >= 0 && irq >= 0) r.set_irq_enabled(irq, false);
}

void SPIClass::endTransaction(void) {
  l6470emu::FirmwareRuntime& r = runtime();
  r.call();
  in_transaction_ = false;
  for (const int n : masked_)
    if (const int irq = l6470emu::arduino::irq_of_interrupt(n); n >= 0 && irq >= 0) r.set_irq_enabled(irq, true);
  r.spend(0);  // what was held off runs now
}

void SPIClass::usingInterrupt(int interruptNumber) {
  for (int& m : masked_)
    if (m < 0 || m == interruptNumber) {
      m = interruptNumber;
      return;
    }
}

void SPIClass::notUsingInterrupt(int interruptNumber) {
  for (int& m : masked_)
    if (m == interruptNumber) m = -1;
}

void SPIClass::setBitOrder(uint8_t bitOrder) {
  runtime().call();
  settings_.bit_order_ = bitOrder;
}

void SPIClass::setDataMode(uint8_t dataMode) {
  runtime().call();
  settings_.data_mode_ = dataMode;
}

void SPIClass::setClockDivider(uint8_t clockDiv) {
  runtime().call();
  settings_.clock_ = divider_clock(clockDiv);
}

void SPIClass::setFrequency(uint32_t freq) {
  runtime().call();
  settings_.clock_ = freq;
}

void SPIClass::bytes(const uint8_t* tx, uint8_t* rx, size_t count) {
  l6470emu::FirmwareRuntime& r = runtime();
  r.call();
  if (controller_ == -2) {
    controller_ = r.controller(name_);
    if (controller_ < 0) {
      std::string names;
      for (const auto& n : r.controller_names()) names += (names.empty() ? "" : ", ") + n;
      r.log(std::string("SPI controller ") + name_ + " is not on the board (its controllers: " + names +
            "): its bytes reach no chip and read 0x00 (spi= in the board description names a chain's controller)");
    }
  }
  if (!begun_) {
    static bool said = false;
    if (!said) r.log(std::string(name_) + ": transfer before begin(): the bytes are clocked anyway");
    said = true;
  }
  if (controller_ < 0) {
    if (rx) std::fill(rx, rx + count, uint8_t{0});
    return;
  }
  l6470emu::BusSettings s;
  s.speed_hz = settings_.clock_ ? settings_.clock_ : 1;
  s.mode = mode_number(settings_.data_mode_);
  s.lsb_first = settings_.bit_order_ == LSBFIRST;
  std::vector<uint8_t> sink;
  if (!rx) {
    sink.resize(count);
    rx = sink.data();
  }
  std::vector<uint8_t> zeros;
  if (!tx) {
    zeros.assign(count, 0);
    tx = zeros.data();
  }
  r.transfer(controller_, s, std::span<const uint8_t>(tx, count), std::span<uint8_t>(rx, count));
}

uint8_t SPIClass::transfer(uint8_t data) {
  uint8_t in = 0;
  bytes(&data, &in, 1);
  return in;
}

uint16_t SPIClass::transfer16(uint16_t data) {
  // The byte that goes first on the wire: the high one MSB first, the low one LSB first.
  const bool lsb = settings_.bit_order_ == LSBFIRST;
  uint8_t tx[2] = {static_cast<uint8_t>(lsb ? data : data >> 8), static_cast<uint8_t>(lsb ? data >> 8 : data)};
  uint8_t rx[2] = {};
  bytes(tx, rx, 2);
  return lsb ? static_cast<uint16_t>(rx[1] << 8 | rx[0]) : static_cast<uint16_t>(rx[0] << 8 | rx[1]);
}

uint32_t SPIClass::transfer32(uint32_t data) {
  const bool lsb = settings_.bit_order_ == LSBFIRST;
  uint8_t tx[4], rx[4] = {};
  for (int i = 0; i < 4; ++i) tx[i] = static_cast<uint8_t>(data >> (lsb ? 8 * i : 24 - 8 * i));
  bytes(tx, rx, 4);
  uint32_t out = 0;
  for (int i = 0; i < 4; ++i) out |= static_cast<uint32_t>(rx[i]) << (lsb ? 8 * i : 24 - 8 * i);
  return out;
}

void SPIClass::transfer(void* buf, size_t count) {
  if (!buf || count == 0) return;
  std::vector<uint8_t> tx(static_cast<uint8_t*>(buf), static_cast<uint8_t*>(buf) + count);
  bytes(tx.data(), static_cast<uint8_t*>(buf), count);
}

void SPIClass::transfer(const void* tx_buf, void* rx_buf, size_t count) {
  if (count == 0) return;
  bytes(static_cast<const uint8_t*>(tx_buf), static_cast<uint8_t*>(rx_buf), count);
}

void SPIClass::transferBytes(const uint8_t* data, uint8_t* out, uint32_t size) { transfer(data, out, size); }
void SPIClass::write(uint8_t data) { transfer(data); }
void SPIClass::write16(uint16_t data) { transfer16(data); }
void SPIClass::write32(uint32_t data) { transfer32(data); }
void SPIClass::writeBytes(const uint8_t* data, uint32_t size) { transfer(data, nullptr, size); }
