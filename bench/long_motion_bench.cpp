// Cost of advancing one chip through a very long stretch of simulated time with the
// event-driven engine: a Move of 2^21 microsteps at the slowest legal profile, and 24
// simulated hours of Run. The goal is under 10 us of wall time each, whatever the length.
#include <benchmark/benchmark.h>

#include <cstdint>

#include "core/chip.hpp"

namespace {

using namespace l6470emu;

/// A chip with ACC = DEC = 1, MAX_SPEED = 1, MIN_SPEED = 0 and the given STEP_SEL.
Chip slowest_chip(std::uint8_t step_sel) {
  Chip c;
  for (std::uint8_t b : {0xA8, 0x05, 0x00, 0x01, 0x06, 0x00, 0x01, 0x07, 0x00, 0x01, 0x08, 0x00, 0x00, 0x16})
    c.on_byte(b);
  c.on_byte(step_sel);
  return c;
}

void send(Chip& c, std::uint8_t op, std::uint32_t arg) {
  c.on_byte(op);
  c.on_byte(static_cast<std::uint8_t>(arg >> 16));
  c.on_byte(static_cast<std::uint8_t>(arg >> 8));
  c.on_byte(static_cast<std::uint8_t>(arg));
}

/// Move of 2^21 microsteps to the end at the slowest profile (full steps: ~38 simulated hours;
/// 1/128: ~18 simulated minutes), then read ABS_POS.
void BM_Move2To21AtTheSlowestProfile(benchmark::State& state) {
  const Chip prepared = slowest_chip(static_cast<std::uint8_t>(state.range(0)));
  Tick simulated = 0;
  for (auto _ : state) {
    Chip c = prepared;
    send(c, 0x41, 1u << 21);
    c.advance_to(Tick{1} << 42);  // ~12 simulated days: more than enough
    benchmark::DoNotOptimize(c.position());
    if (c.position() != (1 << 21) - (1 << 22)) state.SkipWithError("move did not end on target");
    simulated = c.now();
  }
  state.counters["advanced_to_s"] = static_cast<double>(simulated) / kTicksPerSecond;
}
BENCHMARK(BM_Move2To21AtTheSlowestProfile)->ArgName("step_sel")->Arg(0)->Arg(7)->Unit(benchmark::kMicrosecond);

/// Run for 24 simulated hours (ramp up, then cruise), polled once at the end.
void BM_Run24SimulatedHours(benchmark::State& state) {
  const Chip prepared = slowest_chip(7);
  for (auto _ : state) {
    Chip c = prepared;
    send(c, 0x51, 0xFFFFF);
    c.advance_to(24ull * 3600 * kTicksPerSecond);
    benchmark::DoNotOptimize(c.status());
    benchmark::DoNotOptimize(c.position());
  }
  state.counters["simulated_s"] = 24.0 * 3600;
}
BENCHMARK(BM_Run24SimulatedHours)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
