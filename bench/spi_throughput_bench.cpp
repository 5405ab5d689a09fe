// SPI throughput: CS frames per second through a daisy chain of 1..256 L6470s doing
// GetStatus polling, on Chain::select/exchange(span)/deselect directly (no ChainHost,
// no clock advance: the chips are idle, so this measures the byte path and the decoders).
#include <benchmark/benchmark.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "daisychain/chain.hpp"

namespace {

using l6470emu::Chain;

constexpr std::uint8_t kGetStatus = 0xD0;
constexpr std::uint8_t kNop = 0x00;
constexpr int kFramesPerPoll = 3;  // 0xD0 x N, then two frames of NOPs reading STATUS MSB, LSB

/// One GetStatus poll of every chip: three CS frames of N bytes each.
/// Each iteration is one poll; items = CS frames, bytes = bytes clocked.
void BM_GetStatusPolling(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  Chain chain(n);
  const std::vector<std::uint8_t> get_status(n, kGetStatus);
  const std::vector<std::uint8_t> nops(n, kNop);
  std::vector<std::uint8_t> rx_cmd(n), rx_msb(n), rx_lsb(n);

  const auto frame = [&chain](const std::vector<std::uint8_t>& tx, std::vector<std::uint8_t>& rx) {
    chain.select();
    chain.exchange(tx, rx);
    chain.deselect();
  };

  // One poll before timing: it clears the power-up UVLO latch, so every timed poll answers
  // the STATUS the chip shows afterwards (checked below).
  frame(get_status, rx_cmd);
  frame(nops, rx_msb);
  frame(nops, rx_lsb);

  for (auto _ : state) {
    frame(get_status, rx_cmd);
    frame(nops, rx_msb);
    frame(nops, rx_lsb);
    benchmark::DoNotOptimize(rx_lsb.data());
    benchmark::ClobberMemory();
  }

  // The answers must be real: MISO byte k of the two NOP frames is chip k's STATUS.
  for (std::size_t k = 0; k < n; ++k) {
    const auto got = static_cast<std::uint16_t>(rx_msb[k] << 8 | rx_lsb[k]);
    if (got != chain.chip(k).status()) {
      state.SkipWithError("GetStatus answer differs from the chip's STATUS");
      return;
    }
  }

  const auto frames = state.iterations() * kFramesPerPoll;
  state.SetItemsProcessed(frames);                                // items_per_second = CS frames/s
  state.SetBytesProcessed(frames * static_cast<std::int64_t>(n));  // bytes_per_second
  // bytes_per_second above is in binary units (Mi); this one is decimal, as the goal is.
  state.counters["bytes_per_second_SI"] =
      benchmark::Counter(static_cast<double>(frames) * static_cast<double>(n), benchmark::Counter::kIsRate);
  state.counters["chips"] = static_cast<double>(n);
  if (n == 1) state.SetLabel("goal: >= 40M bytes/s (100x a 5 MHz chain with 800 ns CS high)");
}

BENCHMARK(BM_GetStatusPolling)->ArgName("chips")->Arg(1)->Arg(8)->Arg(64)->Arg(256);

}  // namespace

BENCHMARK_MAIN();
