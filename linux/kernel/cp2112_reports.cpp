#include "linux/kernel/cp2112_reports.hpp"

#include <cerrno>

namespace l6470emu {

namespace {

enum : std::uint8_t {
  kGpioConfig = 0x02, kGpioGet = 0x03, kGpioSet = 0x04, kVersion = 0x05, kSmbusConfig = 0x06,
  kReadRequest = 0x10, kWriteReadRequest = 0x11, kReadForceSend = 0x12, kReadResponse = 0x13,
  kWriteRequest = 0x14, kStatusRequest = 0x15, kStatusResponse = 0x16, kCancel = 0x17,
  kLockByte = 0x20, kUsbConfig = 0x21, kManufacturer = 0x22, kProduct = 0x23, kSerial = 0x24,
};

struct ReportSize {
  std::uint8_t id;
  std::uint8_t main_item;  // 0xB1 feature, 0x91 output, 0x81 input
  std::uint8_t bytes;      // after the id
};
constexpr ReportSize kReports[] = {
    {kGpioConfig, 0xB1, 4}, {kGpioGet, 0xB1, 1}, {kGpioSet, 0xB1, 2}, {kVersion, 0xB1, 2},
    {kSmbusConfig, 0xB1, 13}, {kLockByte, 0xB1, 1}, {kUsbConfig, 0xB1, 9}, {kManufacturer, 0xB1, 63},
    {kProduct, 0xB1, 63}, {kSerial, 0xB1, 63},
    {kReadRequest, 0x91, 3}, {kWriteReadRequest, 0x91, 20}, {kReadForceSend, 0x91, 2}, {kWriteRequest, 0x91, 63},
    {kStatusRequest, 0x91, 1}, {kCancel, 0x91, 1}, {kReadResponse, 0x81, 63}, {kStatusResponse, 0x81, 6},
};

std::vector<std::uint8_t> string_report(std::uint8_t id, const std::string& text) {
  // [id, length of what follows the id, USB_DT_STRING, UTF-16LE characters]
  std::vector<std::uint8_t> r{id, 0, 0x03};
  for (char c : text.substr(0, 30)) {
    r.push_back(static_cast<std::uint8_t>(c));
    r.push_back(0);
  }
  r[1] = static_cast<std::uint8_t>(r.size() - 1);
  r.resize(64, 0);
  return r;
}

}  // namespace

Cp2112Reports::Cp2112Reports(Cp2112Pins pins, std::string product, std::string serial)
    : pins_(std::move(pins)), product_(std::move(product)), serial_(std::move(serial)) {
  // Power-up SMBus configuration: 100 kHz, address 0x02, no auto send read, no timeouts.
  smbus_config_ = {kSmbusConfig, 0x00, 0x01, 0x86, 0xA0, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
}

std::vector<std::uint8_t> Cp2112Reports::descriptor() {
  std::vector<std::uint8_t> d = {0x06, 0x00, 0xFF,  // Usage Page (vendor defined 0xFF00)
                                 0x09, 0x01,        // Usage (1)
                                 0xA1, 0x01};       // Collection (Application)
  for (const auto& r : kReports) {
    const std::uint8_t item[] = {0x85, r.id,          // Report ID
                                 0x09, 0x01,          // Usage (1)
                                 0x15, 0x00,          // Logical Minimum (0)
                                 0x26, 0xFF, 0x00,    // Logical Maximum (255)
                                 0x75, 0x08,          // Report Size (8)
                                 0x95, r.bytes,       // Report Count
                                 r.main_item, 0x02};  // Feature / Output / Input (Data, Var, Abs)
    d.insert(d.end(), std::begin(item), std::end(item));
  }
  d.push_back(0xC0);  // End Collection
  return d;
}

std::uint8_t Cp2112Reports::levels() const {
  std::uint8_t v = 0;
  for (unsigned i = 0; i < kCp2112Pins; ++i) {
    bool level;
    if (direction_ & (1u << i))
      level = latch_ & (1u << i);  // the host drives it: it reads back what it wrote
    else if (i < kPinsPerChip)
      level = pins_.level(static_cast<Pin>(i));
    else
      level = true;  // an unused input floats high (weak pull-up)
    if (level) v |= static_cast<std::uint8_t>(1u << i);
  }
  return v;
}

std::vector<std::uint8_t> Cp2112Reports::get(std::uint8_t id) {
  switch (id) {
    case kGpioConfig: return {kGpioConfig, direction_, push_pull_, special_, clock_divider_};
    case kGpioGet: return {kGpioGet, levels()};
    case kVersion: return {kVersion, 0x0C, 0x03};  // part number 0x0C (CP2112), version 3
    case kSmbusConfig: return smbus_config_;
    case kLockByte: return {kLockByte, 0x00};      // every PROM field already programmed: read-only sysfs
    case kUsbConfig: return {kUsbConfig, 0xC4, 0x10, 0x90, 0xEA, 50, 0x01, 1, 0, 0};
    case kManufacturer: return string_report(kManufacturer, "l6470emu");
    case kProduct: return string_report(kProduct, product_);
    case kSerial: return string_report(kSerial, serial_);
    default: return {};
  }
}

int Cp2112Reports::set(std::span<const std::uint8_t> data) {
  if (data.empty()) return EINVAL;
  switch (data[0]) {
    case kGpioConfig:
      if (data.size() < 5) return EINVAL;
      direction_ = data[1];
      push_pull_ = data[2];
      special_ = data[3];
      clock_divider_ = data[4];
      return 0;
    case kGpioSet: {
      if (data.size() < 3) return EINVAL;
      const std::uint8_t mask = data[2];
      latch_ = static_cast<std::uint8_t>((latch_ & ~mask) | (data[1] & mask));
      // A latch reaches the chip only on a pin the host drives and the chip reads.
      for (unsigned i = 0; i < kPinsPerChip; ++i) {
        const Pin pin = static_cast<Pin>(i);
        if ((mask & (1u << i)) && (direction_ & (1u << i)) && !pin_is_chip_output(pin))
          pins_.drive(pin, (latch_ >> i) & 1);
      }
      return 0;
    }
    case kSmbusConfig:
      if (data.size() < smbus_config_.size()) return EINVAL;
      smbus_config_.assign(data.begin(), data.begin() + static_cast<std::ptrdiff_t>(smbus_config_.size()));
      return 0;
    case kLockByte:
    case kUsbConfig:
    case kManufacturer:
    case kProduct:
    case kSerial:
      return 0;  // PROM writes: already programmed, ignored as the bridge does
    default:
      return EIO;
  }
}

std::vector<std::uint8_t> Cp2112Reports::output(std::span<const std::uint8_t> data) {
  if (data.empty()) return {};
  switch (data[0]) {
    case kStatusRequest:  // the last transfer failed: no device acknowledged (address NACK)
      return {kStatusResponse, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00};
    case kReadForceSend:  // nothing was read
      return {kReadResponse, 0x03, 0x00};
    default:
      return {};  // transfer requests and cancels: nothing to answer until asked for status
  }
}

}  // namespace l6470emu
