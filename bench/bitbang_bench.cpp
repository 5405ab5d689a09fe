// SPI bit-banged through the firmware runtime: what one byte costs in CPU time when a program
// clocks it with pin calls (digitalWrite/digitalRead's path: a call's time, then write_pin or
// read_pin), 8 x (MOSI, SCK low, SCK high, MISO read), against three L6470s in virtual time.
// Goal: at most 2 us of CPU time per byte. The controller's byte path beside it for scale.
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <string>

#include "firmware/runtime.hpp"

namespace {

using namespace l6470emu;

constexpr int kCs = 4, kSck = 5, kMosi = 6, kMiso = 7;

BoardConfig config_of(const std::string& text) {
  ParseResult p = parse_board_config(text, "bench");
  if (!p.config) std::abort();
  return *p.config;
}

// limit= as far as it goes: a run of 10^6 s of virtual time is 3 * 10^10 bit-banged bytes.
const std::string kBoard = "chips=3xL6470 cs_pin=D4 sck_pin=D5 mosi_pin=D6 miso_pin=D7 limit=1000000s";

struct Program {
  explicit Program(const std::string& check) : rt(config_of(kBoard + " check=" + check), FirmwareFront::arduino, nullptr) {
    digital_write(kCs, true);
    rt.set_pin_mode(kCs, McuPinMode::output);
    digital_write(kSck, true);
    rt.set_pin_mode(kSck, McuPinMode::output);
    rt.set_pin_mode(kMosi, McuPinMode::output);
    rt.set_pin_mode(kMiso, McuPinMode::input);
  }
  void digital_write(int pin, bool level) {
    rt.call();
    rt.write_pin(pin, level);
  }
  bool digital_read(int pin) {
    rt.call();
    return rt.read_pin(pin);
  }
  std::uint8_t transfer(std::uint8_t out) {
    std::uint8_t in = 0;
    for (int bit = 7; bit >= 0; --bit) {
      digital_write(kMosi, (out >> bit) & 1u);
      digital_write(kSck, false);
      digital_write(kSck, true);
      in = static_cast<std::uint8_t>(in << 1 | digital_read(kMiso));
    }
    return in;
  }
  std::array<std::uint8_t, 3> frame(std::array<std::uint8_t, 3> tx) {
    std::array<std::uint8_t, 3> rx{};
    digital_write(kCs, false);
    for (int k = 0; k < 3; ++k) rx[k] = transfer(tx[k]);
    digital_write(kCs, true);
    return rx;
  }
  FirmwareRuntime rt;
};

/// One GetStatus poll of the three chips, bit-banged: three frames of three bytes. Each
/// iteration is one poll; per_byte is the CPU time of one byte (its 32 pin calls).
void BM_BitBangedGetStatusPoll(benchmark::State& state) {
  Program p(state.range(0) ? "warn" : "off");
  std::uint64_t bytes = 0;
  for (auto _ : state) {
    p.frame({0xD0, 0xD0, 0xD0});
    const auto msb = p.frame({0, 0, 0});
    const auto lsb = p.frame({0, 0, 0});
    benchmark::DoNotOptimize(msb[0] + lsb[2]);
    bytes += 9;
  }
  state.counters["per_byte"] = benchmark::Counter(static_cast<double>(bytes), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.SetLabel(state.range(0) ? "check=warn" : "check=off");
}
BENCHMARK(BM_BitBangedGetStatusPoll)->Arg(1)->Arg(0);

/// The same poll through the SPI controller (SPI.transfer's path), for scale.
void BM_ControllerGetStatusPoll(benchmark::State& state) {
  FirmwareRuntime rt(config_of("chips=3xL6470 cs_pin=D4 limit=1000000s check=warn"), FirmwareFront::arduino, nullptr);
  rt.set_pin_mode(kCs, McuPinMode::output);
  BusSettings mode3;
  mode3.speed_hz = 5'000'000;
  std::uint64_t bytes = 0;
  const auto frame = [&](std::array<std::uint8_t, 3> tx) {
    std::array<std::uint8_t, 3> rx{};
    rt.call();
    rt.write_pin(kCs, false);
    rt.call();
    rt.transfer(0, mode3, tx, rx);
    rt.call();
    rt.write_pin(kCs, true);
    return rx;
  };
  for (auto _ : state) {
    frame({0xD0, 0xD0, 0xD0});
    benchmark::DoNotOptimize(frame({0, 0, 0})[0] + frame({0, 0, 0})[2]);
    bytes += 9;
  }
  state.counters["per_byte"] = benchmark::Counter(static_cast<double>(bytes), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ControllerGetStatusPoll);

}  // namespace

BENCHMARK_MAIN();
