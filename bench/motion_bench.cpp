// Motion: simulated seconds per wall second for a chain of L6470s each running a random
// (fixed-seed) Move/Run profile while the host polls GetStatus of every chip every 1 ms of
// simulated time, once per motion engine (reference and fast) so the two compare side by side,
// and once more with a mechanical axis behind every chip (fast engine) to show what physics costs.
// The workload itself is in motion_workload.hpp, shared with headline.cpp.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "bench/motion_workload.hpp"

namespace {

using namespace l6470emu;

using namespace l6470emu::bench;

/// Each iteration simulates 10 ms (10 polls of every chip).
template <Engine E>
void BM_Motion(benchmark::State& state) {
  constexpr std::uint64_t kMsPerIteration = 10;
  MotionWorkload w(static_cast<std::size_t>(state.range(0)), E);
  const MotionStats before = w.stats();
  for (auto _ : state) w.run_ms(kMsPerIteration);
  const MotionStats& s = w.stats();

  const double sim_seconds = static_cast<double>(state.iterations() * kMsPerIteration) / 1000.0;
  // kIsRate divides by the benchmark's time (real time here: UseRealTime below).
  state.counters["sim_s_per_wall_s"] = benchmark::Counter(sim_seconds, benchmark::Counter::kIsRate);
  state.counters["sim_s"] = sim_seconds;
  state.counters["moves_done"] = static_cast<double>(s.moves_done - before.moves_done);
  state.counters["runs_done"] = static_cast<double>(s.runs_done - before.runs_done);
  state.counters["cmd_errors"] = static_cast<double>(s.cmd_errors - before.cmd_errors);
  state.SetItemsProcessed(static_cast<std::int64_t>(s.polls - before.polls));  // polls of the whole chain per second
  state.SetLabel(engine_name(E));
}

/// The same workload with a mechanical axis behind every chip (bench_axis()): what the
/// physics costs the event-driven engine.
void BM_MotionWithAxes(benchmark::State& state) {
  constexpr std::uint64_t kMsPerIteration = 10;
  MotionWorkload w(static_cast<std::size_t>(state.range(0)), Engine::fast, 0x6470, /*axes=*/true);
  for (auto _ : state) w.run_ms(kMsPerIteration);
  std::int64_t lost_chips = 0;
  for (std::size_t k = 0; k < w.chips(); ++k) lost_chips += w.chain().chip(k).axis()->lost_steps() != 0;
  const double sim_seconds = static_cast<double>(state.iterations() * kMsPerIteration) / 1000.0;
  state.counters["sim_s_per_wall_s"] = benchmark::Counter(sim_seconds, benchmark::Counter::kIsRate);
  state.counters["sim_s"] = sim_seconds;
  state.counters["chips_that_lost_steps"] = static_cast<double>(lost_chips);
  state.SetLabel("fast+axes");
}

BENCHMARK_TEMPLATE(BM_Motion, Engine::reference)->ArgName("chips")->Arg(64)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Motion, Engine::fast)->ArgName("chips")->Arg(64)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MotionWithAxes)->ArgName("chips")->Arg(64)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
