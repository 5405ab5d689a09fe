// l6470emu_bench: the headline figures in a few seconds, next to their goals: SPI
// throughput (GetStatus polling through 1..256 chips), motion speed (64 chips, random
// Move/Run, 1 ms polling) and memory per chip. A plain program, not Google Benchmark;
// for careful numbers run l6470emu_spi_throughput_bench / _motion_bench / _memory_bench.
//
// Usage: l6470emu_bench [seconds per measurement, default 0.5]
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

#include "core/chip.hpp"
#include "core/fast_motion.hpp"
#include "daisychain/chain.hpp"
#include "spi/message.hpp"

#ifndef L6470EMU_BUILD_TYPE
#define L6470EMU_BUILD_TYPE "unknown"
#endif

// ---- heap accounting (as in memory_bench.cpp): every global operator new / delete.
// Nothing allocates inside the timed loops, so this costs the timings nothing.
namespace {

std::size_t g_live_bytes = 0;
constexpr std::size_t kHeader = alignof(std::max_align_t);

void* counted_alloc(std::size_t n) {
  void* raw = std::malloc(n + kHeader);
  if (raw == nullptr) throw std::bad_alloc();
  *static_cast<std::size_t*>(raw) = n;
  g_live_bytes += n;
  return static_cast<char*>(raw) + kHeader;
}

void counted_free(void* p) noexcept {
  if (p == nullptr) return;
  char* raw = static_cast<char*>(p) - kHeader;
  g_live_bytes -= *reinterpret_cast<std::size_t*>(raw);
  std::free(raw);
}

}  // namespace

void* operator new(std::size_t n) { return counted_alloc(n); }
void* operator new[](std::size_t n) { return counted_alloc(n); }
void operator delete(void* p) noexcept { counted_free(p); }
void operator delete[](void* p) noexcept { counted_free(p); }
void operator delete(void* p, std::size_t) noexcept { counted_free(p); }
void operator delete[](void* p, std::size_t) noexcept { counted_free(p); }

namespace {

using namespace l6470emu;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
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

struct SpiResult {
  std::size_t chips;
  double frames_per_second;
  double bytes_per_second;
  double x_real_bus;  ///< frames/s divided by a real chain's frames/s
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
  const auto start = Clock::now();
  double elapsed = 0;
  do {
    for (std::uint64_t i = 0; i < polls_per_batch; ++i) poll();
    polls += polls_per_batch;
    elapsed = seconds_since(start);
  } while (elapsed < min_seconds);

  for (std::size_t k = 0; k < n; ++k)
    if (static_cast<std::uint16_t>(rx_msb[k] << 8 | rx_lsb[k]) != chain.chip(k).status())
      std::fprintf(stderr, "warning: chip %zu of %zu answered a wrong STATUS\n", k, n);

  const double frames = static_cast<double>(polls) * 3;
  const double real_frames_per_second = 1.0 / (static_cast<double>(n) * kRealByteSeconds + kRealCsHighSeconds);
  return {n, frames / elapsed, frames * static_cast<double>(n) / elapsed, frames / elapsed / real_frames_per_second};
}

// ---------------------------------------------------------------- motion
// MotionWorkload is a copy of the one in motion_bench.cpp; keep the two in sync.

/// Which motion engine the chips run; every benchmark is registered once per engine so the
/// rows compare side by side. A further engine = one more case here and one more registration.
using Engine = MotionEngine;

constexpr const char* engine_name(Engine e) {
  switch (e) {
    case Engine::reference: return "reference";
    case Engine::fast: return "fast";
  }
  return "?";
}

/// A chain of `n` default L6470s whose chips use `engine` (set explicitly: the default may change).
Chain make_chain(std::size_t n, Engine engine) {
  Chain chain(n);
  chain.set_motion_engine(engine);
  return chain;
}

struct Axis {
  enum class Phase : std::uint8_t { idle, moving, running, stopping } phase = Phase::idle;
  Tick run_until = 0;
};

struct MotionStats {
  std::uint64_t polls = 0, frames = 0, commands = 0, moves_done = 0, runs_done = 0, cmd_errors = 0;
};

/// N chips behind one chip-select; a host that polls every chip every 1 ms of simulated time
/// and gives each idle axis a random Move or Run (Runs end with SoftStop after 20..300 ms).
/// Bus: 5 MHz SCK, 1 us CS high; every CS frame advances the chain by its own duration.
class MotionWorkload {
 public:
  static constexpr Tick kPollPeriod = ticks_from_ms(1);
  static constexpr std::uint32_t kSckHz = 5'000'000;

  MotionWorkload(std::size_t chips, Engine engine, std::uint64_t seed = 0x6470)
      : chain_(make_chain(chips, engine)),
        rng_(seed),
        axes_(chips),
        status_(chips),
        rx_(chips),
        msb_(chips),
        get_status_(chips, 0xD0),
        nops_(chips, 0x00),
        frame_ticks_(transfer_ticks(static_cast<std::uint32_t>(chips), kSckHz) + BusTiming{}.cs_high_ticks) {
    for (auto& f : cmd_) f.assign(chips, 0x00);
    const StatusLayout& layout = chain_.chip(0).variant().status;
    busy_bit_ = 1u << layout.busy;
    mot_shift_ = static_cast<unsigned>(layout.mot_status);
    error_bits_ = (1u << layout.notperf_cmd) | (1u << layout.wrong_cmd);
    setup_profiles();
    next_poll_ = chain_.now();  // first poll at once; it also clears the power-up UVLO latch
  }

  /// Runs exactly `ms` milliseconds of simulated time: a poll (and the commands it leads to)
  /// at the start of each ms. Calls compose: run_ms(a) then run_ms(b) is run_ms(a + b).
  /// (Exact while the frames of one ms fit in it: 64 chips at 5 MHz need at most 0.7 ms.)
  void run_ms(std::uint64_t ms) {
    for (std::uint64_t i = 0; i < ms; ++i) {
      chain_.advance_to(next_poll_);
      poll();
      command_round();
      next_poll_ += kPollPeriod;
    }
    chain_.advance_to(next_poll_);
  }

  Tick now() const { return chain_.now(); }
  const MotionStats& stats() const { return stats_; }
  std::size_t chips() const { return chain_.size(); }
  const Chain& chain() const { return chain_; }

 private:
  using Bytes = std::vector<std::uint8_t>;

  void frame(const Bytes& tx, Bytes& rx) {
    chain_.advance_to(chain_.now() + frame_ticks_);
    chain_.select();
    chain_.exchange(tx, rx);
    chain_.deselect();
    ++stats_.frames;
  }

  void setup_profiles() {
    struct Param { std::uint8_t address; std::uint32_t lo, hi; };
    constexpr std::array<Param, 3> params{{{0x05, 0x020, 0x400}, {0x06, 0x020, 0x400}, {0x07, 0x020, 0x120}}};
    max_speed_.assign(chips(), 0);
    for (const Param& p : params) {
      std::uniform_int_distribution<std::uint32_t> dist(p.lo, p.hi);
      Bytes addr(chips(), p.address), hi(chips()), lo(chips());
      for (std::size_t k = 0; k < chips(); ++k) {
        const std::uint32_t v = dist(rng_);
        hi[k] = static_cast<std::uint8_t>(v >> 8);
        lo[k] = static_cast<std::uint8_t>(v);
        if (p.address == 0x07) max_speed_[k] = v;
      }
      frame(addr, rx_);
      frame(hi, rx_);
      frame(lo, rx_);
    }
  }

  void poll() {
    frame(get_status_, rx_);
    frame(nops_, msb_);
    frame(nops_, rx_);
    for (std::size_t k = 0; k < chips(); ++k) status_[k] = static_cast<std::uint16_t>(msb_[k] << 8 | rx_[k]);
    ++stats_.polls;
  }

  void command_round() {
    std::size_t longest = 0;
    for (std::size_t k = 0; k < chips(); ++k) {
      const std::uint16_t st = status_[k];
      const bool busy = (st & busy_bit_) == 0;
      const bool stopped = ((st >> mot_shift_) & 3u) == 0;
      if (st & error_bits_) ++stats_.cmd_errors;
      Axis& a = axes_[k];
      switch (a.phase) {
        case Axis::Phase::moving:
          if (!busy) { ++stats_.moves_done; a.phase = Axis::Phase::idle; }
          break;
        case Axis::Phase::running:
          if (chain_.now() >= a.run_until) {
            longest = std::max(longest, put_command(k, {0xB0}));
            a.phase = Axis::Phase::stopping;
          }
          break;
        case Axis::Phase::stopping:
          if (!busy && stopped) { ++stats_.runs_done; a.phase = Axis::Phase::idle; }
          break;
        case Axis::Phase::idle:
          break;
      }
      if (a.phase == Axis::Phase::idle) longest = std::max(longest, start_random_motion(k));
    }
    if (longest == 0) return;
    for (std::size_t f = cmd_.size() - longest; f < cmd_.size(); ++f) {
      frame(cmd_[f], rx_);
      std::fill(cmd_[f].begin(), cmd_[f].end(), 0x00);
    }
  }

  std::size_t start_random_motion(std::size_t k) {
    Axis& a = axes_[k];
    const bool forward = std::uniform_int_distribution<int>(0, 1)(rng_) == 1;
    if (std::uniform_int_distribution<int>(0, 1)(rng_) == 0) {
      const std::uint32_t steps = std::uniform_int_distribution<std::uint32_t>(2'000, 200'000)(rng_);
      a.phase = Axis::Phase::moving;
      return put_command(k, {static_cast<std::uint8_t>(0x40 | forward), steps});
    }
    const std::uint32_t top = max_speed_[k] << 10;
    const std::uint32_t spd = std::uniform_int_distribution<std::uint32_t>(top / 8, top)(rng_);
    a.phase = Axis::Phase::running;
    a.run_until = chain_.now() + ticks_from_ms(std::uniform_int_distribution<std::uint64_t>(20, 300)(rng_));
    return put_command(k, {static_cast<std::uint8_t>(0x50 | forward), spd});
  }

  struct Command {
    std::uint8_t opcode;
    std::uint32_t arg = 0;
    bool has_arg = true;
    Command(std::uint8_t op) : opcode(op), has_arg(false) {}
    Command(std::uint8_t op, std::uint32_t a) : opcode(op), arg(a) {}
  };

  std::size_t put_command(std::size_t k, Command c) {
    ++stats_.commands;
    const std::size_t last = cmd_.size() - 1;
    if (!c.has_arg) {
      cmd_[last][k] = c.opcode;
      return 1;
    }
    cmd_[last - 3][k] = c.opcode;
    cmd_[last - 2][k] = static_cast<std::uint8_t>(c.arg >> 16);
    cmd_[last - 1][k] = static_cast<std::uint8_t>(c.arg >> 8);
    cmd_[last][k] = static_cast<std::uint8_t>(c.arg);
    return 4;
  }

  Chain chain_;
  std::mt19937_64 rng_;
  std::vector<Axis> axes_;
  std::vector<std::uint32_t> max_speed_;
  std::vector<std::uint16_t> status_;
  Bytes rx_, msb_, get_status_, nops_;
  std::array<Bytes, 4> cmd_;
  Tick frame_ticks_;
  Tick next_poll_ = 0;
  std::uint16_t busy_bit_ = 0, error_bits_ = 0;
  unsigned mot_shift_ = 0;
  MotionStats stats_;
};

constexpr std::size_t kMotionChips = 64;
constexpr double kGoalSimPerWall = 1000.0;

struct MotionResult {
  Engine engine;
  double sim_seconds;
  double wall_seconds;
  MotionStats stats;
  double ratio() const { return sim_seconds / wall_seconds; }
};

MotionResult measure_motion(MotionWorkload& w, Engine engine, double min_seconds) {
  const MotionStats before = w.stats();
  const Tick sim_start = w.now();
  const auto start = Clock::now();
  double elapsed = 0;
  do {
    w.run_ms(1);
    elapsed = seconds_since(start);
  } while (elapsed < min_seconds);
  MotionStats s = w.stats();
  s.polls -= before.polls;
  s.moves_done -= before.moves_done;
  s.runs_done -= before.runs_done;
  s.cmd_errors -= before.cmd_errors;
  return {engine, static_cast<double>(w.now() - sim_start) / static_cast<double>(kTicksPerSecond), elapsed, s};
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
  const std::size_t before = g_live_bytes;
  const Chain chain(kMemoryChips);
  return static_cast<double>(sizeof(Chain) + (g_live_bytes - before)) / static_cast<double>(chain.size());
}

const char* verdict(bool met) { return met ? "met" : "NOT MET"; }

}  // namespace

int main(int argc, char** argv) {
  double seconds = 0.5;
  if (argc > 1) seconds = std::strtod(argv[1], nullptr);
  if (!(seconds > 0)) {
    std::fprintf(stderr, "usage: %s [seconds per measurement, default 0.5]\n", argv[0]);
    return 2;
  }

  std::printf("l6470emu headline benchmark  (build: %s%s, one thread, steady_clock, %.2g s per measurement)\n\n",
              L6470EMU_BUILD_TYPE,
#ifdef NDEBUG
              "",
#else
              ", ASSERTS ON: numbers not representative",
#endif
              seconds);

  // SPI
  std::printf("SPI throughput: GetStatus polling of every chip (0xD0 x N, 2 x NOP x N), Chain::select/exchange/deselect\n");
  std::printf("  %6s  %12s  %12s  %9s  %10s  %-22s  %s\n", "chips", "frames/s", "bytes/s", "ns/byte", "x real bus", "goal", "");
  for (const std::size_t n : {std::size_t{1}, std::size_t{8}, std::size_t{64}, std::size_t{256}}) {
    const SpiResult r = measure_spi(n, seconds);
    const std::string frames = si(r.frames_per_second), bytes = si(r.bytes_per_second) + "B";
    char x[16];
    std::snprintf(x, sizeof x, "%.0fx", r.x_real_bus);
    if (n == 1)
      std::printf("  %6zu  %12s  %12s  %9.1f  %10s  %-22s  %s\n", n, frames.c_str(), bytes.c_str(), 1e9 / r.bytes_per_second,
                  x, ">= 40 MB/s (100x real)", verdict(r.bytes_per_second >= kGoalOneChipBytesPerSecond));
    else
      std::printf("  %6zu  %12s  %12s  %9.1f  %10s  %-22s\n", n, frames.c_str(), bytes.c_str(), 1e9 / r.bytes_per_second, x, "-");
  }
  std::printf("  real bus: 5 MHz SCK, 800 ns CS high between frames (1 chip: 417k frames/s = 417 kB/s)\n\n");

  // Motion
  std::printf("Motion: %zu chips, random Move/Run (fixed seed), GetStatus of every chip every 1 ms simulated, 5 MHz bus\n",
              kMotionChips);
  std::printf("  %-10s  %14s  %9s  %9s  %6s  %5s  %9s  %s\n", "engine", "sim s/wall s", "sim s", "wall s", "moves", "runs",
              "goal", "");
  constexpr std::array kEngines{Engine::reference, Engine::fast};
  std::vector<MotionWorkload> runs;  // kept for the cross-check below
  runs.reserve(kEngines.size());
  std::vector<double> ratios;
  for (const Engine e : kEngines) {
    const MotionResult r = measure_motion(runs.emplace_back(kMotionChips, e), e, seconds);
    ratios.push_back(r.ratio());
    char ratio[32];
    std::snprintf(ratio, sizeof ratio, r.ratio() >= 10 ? "%.0fx" : "%.3fx", r.ratio());
    std::printf("  %-10s  %14s  %9.3f  %9.3f  %6llu  %5llu  %9s  %s\n", engine_name(e), ratio, r.sim_seconds,
                r.wall_seconds, static_cast<unsigned long long>(r.stats.moves_done),
                static_cast<unsigned long long>(r.stats.runs_done), e == Engine::fast ? ">= 1000x" : "(cross-check)",
                e == Engine::fast ? verdict(r.ratio() >= kGoalSimPerWall) : "");
    if (r.stats.cmd_errors != 0)
      std::printf("  warning: %llu polls showed NOTPERF_CMD/WRONG_CMD\n", static_cast<unsigned long long>(r.stats.cmd_errors));
  }
  std::printf("  fast engine / reference engine: %.0fx\n", ratios[1] / ratios[0]);
  // The fast row only counts if the fast engine did the same work: replay the reference run's
  // simulated time with the fast engine and compare every chip's motion state and STATUS.
  {
    const MotionWorkload& ref = runs.front();
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
