// l6470emu_bench: the headline figures in a few seconds, next to their goals: SPI
// throughput (GetStatus polling through 1..256 chips), motion speed (64 chips, random
// Move/Run, 1 ms polling) and memory per chip. A plain program, not Google Benchmark;
// for careful numbers run l6470emu_spi_throughput_bench / _motion_bench / _memory_bench.
//
// Usage: l6470emu_bench [--no-verdicts] [seconds per measurement, default 0.5]
#include <algorithm>
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <random>
#include <string>
#include <vector>

#include <time.h>

#include "bench/heap_counter.hpp"
#include "bench/motion_workload.hpp"
#include "core/chip.hpp"
#include "core/fast_motion.hpp"
#include "daisychain/chain.hpp"
#include "spi/message.hpp"

#ifndef L6470EMU_BUILD_TYPE
#define L6470EMU_BUILD_TYPE "unknown"
#endif


namespace {

using namespace l6470emu;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// CPU seconds this thread has run. On a loaded machine a measurement's wall time includes the
/// time other processes had the CPU; work per CPU second is what an idle machine's wall figure
/// approaches (the goals are judged on wall time).
double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

/// "12.3 M" style numbers.
std::string si(double v) {
  const char* unit = "";
  if (v >= 1e9) { v /= 1e9; unit = " G"; }
  else if (v >= 1e6) { v /= 1e6; unit = " M"; }
  else if (v >= 1e3) { v /= 1e3; unit = " k"; }
  char buf[32];
  std::snprintf(buf, sizeof buf, v >= 100 ? "%.0f%s" : v >= 10 ? "%.1f%s" : "%.2f%s", v, unit);
  return buf;
}

// ---------------------------------------------------------------- SPI throughput

/// The real bus the goals compare with: 5 MHz SCK (1.6 us per byte), 800 ns CS high per frame.
constexpr double kRealByteSeconds = 8.0 / 5e6;
constexpr double kRealCsHighSeconds = 800e-9;
constexpr double kGoalOneChipBytesPerSecond = 40e6;
constexpr double kGoalChainBytesPerSecond = 250e6;  ///< 8..256 chips

struct SpiResult {
  std::size_t chips;
  double frames_per_second;
  double bytes_per_second;
  double x_real_bus;  ///< frames/s divided by a real chain's frames/s
  double on_cpu;      ///< CPU seconds / wall seconds of the measurement
};

/// GetStatus polling as in spi_throughput_bench.cpp: 0xD0 x N, then two NOP frames; Chain only.
SpiResult measure_spi(std::size_t n, double min_seconds) {
  Chain chain(n);
  const std::vector<std::uint8_t> get_status(n, 0xD0), nops(n, 0x00);
  std::vector<std::uint8_t> rx_cmd(n), rx_msb(n), rx_lsb(n);
  const auto frame = [&chain](const std::vector<std::uint8_t>& tx, std::vector<std::uint8_t>& rx) {
    chain.select();
    chain.exchange(tx, rx);
    chain.deselect();
  };
  const auto poll = [&] {
    frame(get_status, rx_cmd);
    frame(nops, rx_msb);
    frame(nops, rx_lsb);
  };
  poll();  // clears the power-up UVLO latch

  const std::uint64_t polls_per_batch = std::max<std::uint64_t>(1, 16384 / n);
  std::uint64_t polls = 0;
  const double cpu_start = thread_cpu_seconds();
  const auto start = Clock::now();
  double elapsed = 0;
  do {
    for (std::uint64_t i = 0; i < polls_per_batch; ++i) poll();
    polls += polls_per_batch;
    elapsed = seconds_since(start);
  } while (elapsed < min_seconds);
  const double cpu = thread_cpu_seconds() - cpu_start;

  for (std::size_t k = 0; k < n; ++k)
    if (static_cast<std::uint16_t>(rx_msb[k] << 8 | rx_lsb[k]) != chain.chip(k).status())
      std::fprintf(stderr, "warning: chip %zu of %zu answered a wrong STATUS\n", k, n);

  const double frames = static_cast<double>(polls) * 3;
  const double real_frames_per_second = 1.0 / (static_cast<double>(n) * kRealByteSeconds + kRealCsHighSeconds);
  return {n, frames / elapsed, frames * static_cast<double>(n) / elapsed, frames / elapsed / real_frames_per_second,
          cpu / elapsed};
}

// ---------------------------------------------------------------- motion
// The workload is bench/motion_workload.hpp, shared with motion_bench.cpp.
using namespace l6470emu::bench;

constexpr std::size_t kMotionChips = 64;
constexpr double kGoalSimPerWall = 3000.0;
constexpr double kGoalAxisCost = 1.15;  ///< time with an axis behind every chip / without

struct MotionResult {
  Engine engine;
  double sim_seconds;
  double wall_seconds;
  double cpu_seconds;
  MotionStats stats;
  double ratio() const { return sim_seconds / wall_seconds; }
  double cpu_ratio() const { return sim_seconds / cpu_seconds; }
};

MotionResult measure_motion(MotionWorkload& w, Engine engine, double min_seconds) {
  const MotionStats before = w.stats();
  const Tick sim_start = w.now();
  const double cpu_start = thread_cpu_seconds();
  const auto start = Clock::now();
  double elapsed = 0;
  do {
    w.run_ms(64);  // the clock is read every 64 simulated ms: a read costs ~7% of one ms's work
    elapsed = seconds_since(start);
  } while (elapsed < min_seconds);
  const double cpu = thread_cpu_seconds() - cpu_start;
  MotionStats s = w.stats();
  s.polls -= before.polls;
  s.moves_done -= before.moves_done;
  s.runs_done -= before.runs_done;
  s.cmd_errors -= before.cmd_errors;
  return {engine, static_cast<double>(w.now() - sim_start) / static_cast<double>(kTicksPerSecond), elapsed, cpu, s};
}

/// Measures two workloads in alternating slices (a, b, a, b, ...), `seconds` of wall time each
/// in all, so that a change in the machine's load falls on both alike.
std::array<MotionResult, 2> measure_alternating(MotionWorkload& a, MotionWorkload& b, double seconds, int slices = 8) {
  std::array<MotionResult, 2> total{MotionResult{Engine::fast, 0, 0, 0, {}}, MotionResult{Engine::fast, 0, 0, 0, {}}};
  for (int i = 0; i < slices; ++i)
    for (int j = 0; j < 2; ++j) {
      const MotionResult r = measure_motion(j == 0 ? a : b, Engine::fast, seconds / slices);
      MotionResult& t = total[j];
      t.sim_seconds += r.sim_seconds;
      t.wall_seconds += r.wall_seconds;
      t.cpu_seconds += r.cpu_seconds;
      t.stats.polls += r.stats.polls;
      t.stats.moves_done += r.stats.moves_done;
      t.stats.runs_done += r.stats.runs_done;
      t.stats.cmd_errors += r.stats.cmd_errors;
    }
  return total;
}

/// Whether two workloads (same seed, same simulated time) left every chip in the same state.
bool same_chips(const MotionWorkload& a, const MotionWorkload& b) {
  if (a.now() != b.now() || a.chips() != b.chips()) return false;
  for (std::size_t k = 0; k < a.chips(); ++k)
    if (!(a.chain().chip(k).motion() == b.chain().chip(k).motion()) || a.chain().chip(k).status() != b.chain().chip(k).status())
      return false;
  return true;
}

// ---------------------------------------------------------------- memory

constexpr std::size_t kMemoryChips = 256;
constexpr double kGoalBytesPerChip = 1024.0;

/// (sizeof(Chain) + heap the chain owns) / chips, for a chain of 256.
double measure_bytes_per_chip() {
  const std::size_t before = live_heap_bytes();
  const Chain chain(kMemoryChips);
  return static_cast<double>(sizeof(Chain) + (live_heap_bytes() - before)) / static_cast<double>(chain.size());
}

bool g_verdicts = true;  ///< --no-verdicts: goals are printed, "met" / "NOT MET" is not

const char* verdict(bool met) { return !g_verdicts ? "" : met ? "met" : "NOT MET"; }

/// "87%": the share of a measurement's wall time this thread was on a CPU.
std::string percent(double share) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%.0f%%", share * 100);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 0.5;
  bool usage = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--no-verdicts") {
      g_verdicts = false;
    } else {
      char* end = nullptr;
      seconds = std::strtod(argv[i], &end);
      usage = usage || end == argv[i] || *end != '\0';
    }
  }
  if (usage || !(seconds > 0)) {
    std::fprintf(stderr,
                 "usage: %s [--no-verdicts] [seconds per measurement, default 0.5]\n"
                 "  --no-verdicts  print the figures and their goals without judging them (CI: machines are noisy)\n",
                 argv[0]);
    return 2;
  }

  std::printf("l6470emu headline benchmark  (build: %s%s, one thread, steady_clock, %.2g s per measurement)\n",
              L6470EMU_BUILD_TYPE,
#ifdef NDEBUG
              "",
#else
              ", ASSERTS ON: numbers not representative",
#endif
              seconds);
  std::printf("Figures are per wall second; \"on CPU\" is the share of the wall time this thread ran: below ~95%%\n"
              "the machine was busy, and figure / share is what an idle machine would show.\n\n");

  // SPI
  std::printf("SPI throughput: GetStatus polling of every chip (0xD0 x N, 2 x NOP x N), Chain::select/exchange/deselect\n");
  std::printf("  %6s  %12s  %12s  %9s  %10s  %6s  %-22s  %s\n", "chips", "frames/s", "bytes/s", "ns/byte", "x real bus",
              "on CPU", "goal", "");
  for (const std::size_t n : {std::size_t{1}, std::size_t{8}, std::size_t{64}, std::size_t{256}}) {
    const SpiResult r = measure_spi(n, seconds);
    const std::string frames = si(r.frames_per_second), bytes = si(r.bytes_per_second) + "B";
    char x[16];
    std::snprintf(x, sizeof x, "%.0fx", r.x_real_bus);
    const bool one = n == 1;
    std::printf("  %6zu  %12s  %12s  %9.1f  %10s  %6s  %-22s  %s\n", n, frames.c_str(), bytes.c_str(),
                1e9 / r.bytes_per_second, x, percent(r.on_cpu).c_str(), one ? ">= 40 MB/s (100x real)" : ">= 250 MB/s",
                verdict(r.bytes_per_second >= (one ? kGoalOneChipBytesPerSecond : kGoalChainBytesPerSecond)));
  }
  std::printf("  real bus: 5 MHz SCK, 800 ns CS high between frames (1 chip: 417k frames/s = 417 kB/s)\n\n");

  // Motion
  std::printf("Motion: %zu chips, random Move/Run (fixed seed), GetStatus of every chip every 1 ms simulated, 5 MHz bus\n",
              kMotionChips);
  std::printf("  %-10s  %14s  %6s  %9s  %9s  %6s  %5s  %9s  %s\n", "engine", "sim s/wall s", "on CPU", "sim s", "wall s",
              "moves", "runs", "goal", "");
  // The reference engine alone; the fast engine without and with a mechanical axis behind every
  // chip (bench_axis(): motor, load, stops, switch) in alternating slices, for a fair axis cost.
  MotionWorkload ref(kMotionChips, Engine::reference);  // kept for the cross-check below
  MotionWorkload fast(kMotionChips, Engine::fast);
  MotionWorkload axes(kMotionChips, Engine::fast, 0x6470, /*axes=*/true);
  const MotionResult ref_result = measure_motion(ref, Engine::reference, seconds);
  const std::array<MotionResult, 2> fast_results = measure_alternating(fast, axes, seconds);
  for (const MotionResult& r : {ref_result, fast_results[0]}) {
    const Engine e = r.engine;
    char ratio[32];
    std::snprintf(ratio, sizeof ratio, r.ratio() >= 10 ? "%.0fx" : "%.3fx", r.ratio());
    std::printf("  %-10s  %14s  %6s  %9.3f  %9.3f  %6llu  %5llu  %9s  %s\n", engine_name(e), ratio,
                percent(r.cpu_seconds / r.wall_seconds).c_str(), r.sim_seconds, r.wall_seconds,
                static_cast<unsigned long long>(r.stats.moves_done), static_cast<unsigned long long>(r.stats.runs_done),
                e == Engine::fast ? ">= 3000x" : "(cross-check)", e == Engine::fast ? verdict(r.ratio() >= kGoalSimPerWall) : "");
    if (r.stats.cmd_errors != 0)
      std::printf("  warning: %llu polls showed NOTPERF_CMD/WRONG_CMD\n", static_cast<unsigned long long>(r.stats.cmd_errors));
  }
  std::printf("  fast engine / reference engine: %.0fx\n", fast_results[0].ratio() / ref_result.ratio());
  {
    const MotionResult& r = fast_results[1];
    std::size_t lost = 0;
    for (std::size_t k = 0; k < axes.chips(); ++k) lost += axes.chain().chip(k).axis()->lost_steps() != 0;
    // Per CPU second: the two workloads alternate, but a busy machine still takes the CPU away
    // from one slice more than from another; CPU time is what each workload itself cost.
    const double cost = fast_results[0].cpu_ratio() / r.cpu_ratio();
    std::printf("  %-10s  %13.0fx  %6s  %9.3f  %9.3f  %6llu  %5llu  (%zu of %zu axes lost steps; costs %.2fx the CPU time without"
                " axes; goal <= %.2fx%s%s)\n",
                "fast+axes", r.ratio(), percent(r.cpu_seconds / r.wall_seconds).c_str(), r.sim_seconds, r.wall_seconds,
                static_cast<unsigned long long>(r.stats.moves_done), static_cast<unsigned long long>(r.stats.runs_done), lost,
                axes.chips(), cost, kGoalAxisCost, g_verdicts ? " " : "", verdict(cost <= kGoalAxisCost));
  }
  // The fast row only counts if the fast engine did the same work: replay the reference run's
  // simulated time with the fast engine and compare every chip's motion state and STATUS.
  {
    MotionWorkload check(kMotionChips, Engine::fast);
    const std::uint64_t ms = (ref.now() - check.now()) / MotionWorkload::kPollPeriod;
    check.run_ms(ms);
    std::printf("  cross-check: fast engine after the reference run's %llu ms simulated: %s\n",
                static_cast<unsigned long long>(ms), same_chips(ref, check) ? "every chip identical" : "DIFFERS FROM REFERENCE");
  }
  std::printf("\n");

  // Long motion: cost independent of simulated time
  std::printf("Long motion, one chip, event-driven engine (ACC = DEC = MAX_SPEED = 1, MIN_SPEED = 0)\n");
  std::printf("  %-44s  %12s  %s\n", "case", "wall per run", "goal");
  {
    const auto time_it = [&](auto&& body) {
      using clock = std::chrono::steady_clock;
      std::uint64_t runs_done = 0;
      const auto start = clock::now();
      double elapsed = 0;
      do {
        for (int i = 0; i < 1000; ++i) body();
        runs_done += 1000;
        elapsed = std::chrono::duration<double>(clock::now() - start).count();
      } while (elapsed < seconds / 4);
      return elapsed / static_cast<double>(runs_done);
    };
    const auto slowest = [](std::uint8_t step_sel) {
      Chip c;
      for (std::uint8_t b : {0xA8, 0x05, 0x00, 0x01, 0x06, 0x00, 0x01, 0x07, 0x00, 0x01, 0x08, 0x00, 0x00, 0x16}) c.on_byte(b);
      c.on_byte(step_sel);
      return c;
    };
    const auto send3 = [](Chip& c, std::uint8_t op, std::uint32_t arg) {
      for (std::uint8_t b : {op, static_cast<std::uint8_t>(arg >> 16), static_cast<std::uint8_t>(arg >> 8),
                             static_cast<std::uint8_t>(arg)})
        c.on_byte(b);
    };
    for (std::uint8_t sel : {std::uint8_t{0}, std::uint8_t{7}}) {
      const Chip prepared = slowest(sel);
      bool on_target = true;
      const double t = time_it([&] {
        Chip c = prepared;
        send3(c, 0x41, 1u << 21);
        c.advance_to(Tick{1} << 42);
        on_target = on_target && c.position() == -(1 << 21) && c.busy_sync_pin();
      });
      char name[64];
      std::snprintf(name, sizeof name, "Move 2^21 microsteps, STEP_SEL %u%s", sel, on_target ? "" : " (WRONG END)");
      std::printf("  %-44s  %9.2f us  < 10 us  %s\n", name, t * 1e6, verdict(t < 10e-6 && on_target));
    }
    const Chip prepared = slowest(7);
    const double t = time_it([&] {
      Chip c = prepared;
      send3(c, 0x51, 0xFFFFF);
      c.advance_to(24ull * 3600 * kTicksPerSecond);
      volatile auto keep = c.position();
      (void)keep;
    });
    std::printf("  %-44s  %9.2f us  < 10 us  %s\n\n", "Run for 24 simulated hours", t * 1e6, verdict(t < 10e-6));
  }

  // Memory
  const double per_chip = measure_bytes_per_chip();
  std::printf("Memory\n");
  std::printf("  %-34s  %8zu bytes\n", "sizeof(Chip)", sizeof(Chip));
  std::printf("  %-34s  %8.1f bytes   goal < 1 KiB  %s\n", "per chip in a Chain of 256 (*)", per_chip,
              verdict(per_chip < kGoalBytesPerChip));
  std::printf("  (*) (sizeof(Chain) + heap the chain owns) / 256: the Chip, its shift-register byte, its share of Chain\n");
  return 0;
}
