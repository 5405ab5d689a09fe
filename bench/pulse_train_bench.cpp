// Cost of a step clock from a timer: an L6474 on a firmware runtime, its STCK driven by a
// 10 kHz timer for one simulated second and for one simulated hour (no callback: the board
// applies the pulses in bulk), then ABS_POS read. The goal: the hour costs no more than the
// second. For comparison, the same second with an update callback per pulse (met one by one),
// and the hour's pulses as 36 million single STCK edges on a bare chip.
#include <benchmark/benchmark.h>

#include <cstdint>

#include "core/chip.hpp"
#include "firmware/runtime.hpp"

namespace {

using namespace l6470emu;

/// A runtime with one enabled L6474 whose STCK is PB10, and a 10 kHz timer (84 MHz, prescaler
/// 84, period 100) on it; `callback` adds an update interrupt that only counts.
struct Rig {
  explicit Rig(bool callback)
      : rt(*parse_board_config("chips=L6474 cs_pin=PB6 stck_pin=PB10 dir_pin=PA8 limit=7200s", "bench").config,
           FirmwareFront::stm32_hal, {}) {
    rt.board().drive_pin(0, 0, Pin::DIR, true);
    rt.board().with_chain(0, [](Chain& c) { c.chip(0).on_byte_at(c.now(), 0xB8); });  // Enable
    FirmwareTimers& t = rt.timers();
    timer = t.add("TIM3");
    t.set_clock(timer, 84'000'000);
    t.set_prescaler(timer, 84);
    t.set_period(timer, 100);
    t.set_compare(timer, 50);
    t.set_output(timer, FirmwareRuntime::key_of(*parse_mcu_pin("PB10")));
    if (callback) t.set_update_irq(timer, rt.add_irq([this] { ++updates; }));
  }
  FirmwareRuntime rt;
  int timer = -1;
  std::uint64_t updates = 0;
};

void run_train(benchmark::State& state, Tick simulated, bool callback) {
  std::int32_t position = 0;
  for (auto _ : state) {
    Rig r(callback);
    r.rt.timers().start(r.timer);
    r.rt.sleep_until(simulated - 1);
    r.rt.board().with_chain(0, [&](Chain& c) { position = c.chip(0).position(); });
    benchmark::DoNotOptimize(position);
  }
  const auto expected = static_cast<std::int32_t>((simulated - 1) / 400 + 1) & 0x3FFFFF;
  if ((position & 0x3FFFFF) != expected) state.SkipWithError("ABS_POS is not the pulses given");
  state.counters["pulses"] = static_cast<double>((simulated - 1) / 400 + 1);
}

void BM_TenKilohertzForOneSecond(benchmark::State& state) { run_train(state, kTicksPerSecond, false); }
void BM_TenKilohertzForOneHour(benchmark::State& state) { run_train(state, 3600 * kTicksPerSecond, false); }
void BM_TenKilohertzForOneSecondWithAnUpdateCallback(benchmark::State& state) {
  run_train(state, kTicksPerSecond, true);
}

/// The hour's 36 000 000 pulses as single edges on a bare chip: what bulk stepping avoids.
void BM_OneHourOfSingleStckEdgesOnABareChip(benchmark::State& state) {
  for (auto _ : state) {
    Chip c(l6474());
    c.set_dir_pin(true);
    c.on_byte(0xB8);
    for (std::uint32_t i = 0; i < 36'000'000; ++i) {
      c.set_stck_pin(true);
      c.set_stck_pin(false);
    }
    benchmark::DoNotOptimize(c.position());
  }
}

BENCHMARK(BM_TenKilohertzForOneSecond)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TenKilohertzForOneHour)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TenKilohertzForOneSecondWithAnUpdateCallback)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OneHourOfSingleStckEdgesOnABareChip)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
