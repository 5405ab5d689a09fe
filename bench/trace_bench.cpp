// Trace benchmarks: replaying a native trace of 10 million frames from disk (parse, drive
// the emulated chain, compare every MISO byte; goal >= 2 M frames/s), importing a Saleae
// Logic 2 CSV export (goal >= 50 MB/s), and recording a host that polls STATUS for a minute
// as plain or gzip, one line per frame or with `repeat` lines (file sizes as counters).
// The inputs are generated here, in /tmp, not committed.
#include <benchmark/benchmark.h>

#include <sys/stat.h>

#include <cstdio>
#include <random>
#include <string>
#include <unistd.h>

#include "daisychain/recording_chain.hpp"
#include "daisychain/replay.hpp"
#include "spi/trace_import.hpp"
#include "spi/trace_native.hpp"

namespace {

using namespace l6470emu;

constexpr std::size_t kChips = 3;

/// Records `frames` CS frames of a 3-chip chain into a native trace at `path`: a host polling
/// every chip's STATUS (3 frames) and ABS_POS (4 frames) every 100 µs and, every 10 ms, giving
/// each chip a Move or a Run at random. The MISO bytes are the emulator's own, so a replay
/// must match everywhere.
void record_trace(const std::string& path, std::uint64_t frames) {
  Chain chain(kChips);
  NativeTraceWriter writer(path, NativeWriteOptions{/*flush_each_event=*/false, /*compact=*/false});
  RecordingChain rec(chain, writer, RecordOptions{.observe_outputs = false, .board = {}});
  std::mt19937 rng(6470);
  std::vector<std::uint8_t> tx(kChips), rx(kChips);
  auto frame = [&](std::uint8_t b0, std::uint8_t b1, std::uint8_t b2) {
    rec.advance_to(rec.now() + 4);
    rec.select();
    tx = {b0, b1, b2};
    rec.advance_to(rec.now() + 3 * 7);
    rec.exchange(tx, rx);
    rec.deselect();
  };
  std::uint64_t n = 0, cycle = 0;
  while (n < frames) {
    frame(0xD0, 0xD0, 0xD0);
    frame(0, 0, 0);
    frame(0, 0, 0);
    frame(0x21, 0x21, 0x21);
    frame(0, 0, 0);
    frame(0, 0, 0);
    frame(0, 0, 0);
    n += 7;
    if (++cycle % 100 == 0) {
      const std::uint32_t steps = std::uniform_int_distribution<std::uint32_t>(100, 20000)(rng);
      const std::uint8_t op = (rng() & 1) ? 0x41 : 0x51;
      frame(op, op ^ 1, op);
      frame(0, 0, 0);
      frame(static_cast<std::uint8_t>(steps >> 8), static_cast<std::uint8_t>(steps >> 8), 0x10);
      frame(static_cast<std::uint8_t>(steps), static_cast<std::uint8_t>(steps), 0x00);
      n += 4;
    }
    rec.advance_to(rec.now() + ticks_from_us(100));
  }
}

std::string temp_path(const char* name) { return "/tmp/l6470emu-bench-" + std::to_string(getpid()) + "-" + name; }

void BM_ReplayNativeTrace(benchmark::State& state) {
  const auto frames = static_cast<std::uint64_t>(state.range(0));
  const std::string path = temp_path("replay.trace");
  record_trace(path, frames);
  ReplayResult r;
  for (auto _ : state) {
    NativeTraceReader reader(path, /*max_frames=*/0);  // its own trace: no limit (the default stops at 10 M)
    Chain chain(kChips);
    r = replay_trace(reader, chain);
  }
  std::remove(path.c_str());
  if (!r.matched()) {
    state.SkipWithError("the replay diverged from its own recording");
    return;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(r.frames) * state.iterations());  // items/s = frames/s
  state.counters["frames"] = static_cast<double>(r.frames);
}
BENCHMARK(BM_ReplayNativeTrace)->Arg(10'000'000)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

/// A Logic 2 analyzer export of about `bytes` bytes: 1-byte frames (enable, result, disable).
std::string saleae_csv(std::size_t bytes) {
  std::string s = "name,type,start_time,duration,\"mosi\",\"miso\"\n";
  s.reserve(bytes + 256);
  char line[160];
  double t = 0.4118532;
  std::uint8_t v = 0;
  while (s.size() < bytes) {
    const int n = std::snprintf(line, sizeof line,
                                "\"SPI\",\"enable\",%.9f,2e-08,,\n\"SPI\",\"result\",%.9f,0.000001520,0x%02X,0x%02X\n"
                                "\"SPI\",\"disable\",%.9f,2e-08,,\n",
                                t, t + 2.5e-7, v, static_cast<std::uint8_t>(v * 7), t + 1.9e-6);
    s.append(line, static_cast<std::size_t>(n));
    t += 4e-6;
    ++v;
  }
  return s;
}

void BM_ImportSaleaeCsv(benchmark::State& state) {
  const std::string csv = saleae_csv(static_cast<std::size_t>(state.range(0)) << 20);
  std::size_t frames = 0;
  for (auto _ : state) {
    const Trace t = import_saleae_csv(csv, "bench.csv");
    frames = t.frame_count();
    benchmark::DoNotOptimize(frames);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(csv.size()) * state.iterations());  // bytes/s = MB/s
  state.counters["frames"] = static_cast<double>(frames);
}
BENCHMARK(BM_ImportSaleaeCsv)->Arg(100)->Unit(benchmark::kMillisecond)->UseRealTime();

/// A one-chip host as vendor examples write it, recorded as a running board records: every
/// event flushed. For a minute of virtual time it polls GetStatus every millisecond (a frame
/// per byte) and, every 10 s, starts a 200-step Move and polls until it ends.
/// Returns the frames recorded.
std::uint64_t record_polling_host(const std::string& path, NativeWriteOptions options) {
  Chain chain(1);
  NativeTraceWriter writer(path, options);
  RecordingChain rec(chain, writer);
  std::vector<std::uint8_t> rx(1);
  auto frame = [&](std::uint8_t b) {
    rec.advance_to(rec.now() + 8);
    rec.select();
    const std::uint8_t tx[1] = {b};
    rec.advance_to(rec.now() + 7);
    rec.exchange(tx, rx);
    rec.deselect();
  };
  const Tick start = rec.now();
  for (std::uint64_t ms = 0; ms < 60'000; ++ms) {
    rec.advance_to(start + ticks_from_ms(ms));
    rec.observe_outputs();
    if (ms % 10'000 == 5'000) {  // Move(FWD, 25600 microsteps)
      for (std::uint8_t b : {std::uint8_t{0x41}, std::uint8_t{0x00}, std::uint8_t{0x64}, std::uint8_t{0x00}}) frame(b);
    }
    frame(0xD0);
    frame(0x00);
    frame(0x00);
  }
  writer.finish();
  return rec.frames_recorded();
}

std::uint64_t file_size(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? static_cast<std::uint64_t>(st.st_size) : 0;
}

/// Arg: 0 = plain, one line per frame (as before compaction); 1 = plain with `repeat` lines;
/// 2 = gzip, one line per frame; 3 = gzip with `repeat` lines.
void BM_RecordPollingHost(benchmark::State& state) {
  const bool compact = state.range(0) % 2 == 1, gzip = state.range(0) >= 2;
  const std::string path = temp_path(gzip ? "poll.trace.gz" : "poll.trace");
  std::uint64_t frames = 0;
  for (auto _ : state) frames = record_polling_host(path, NativeWriteOptions{true, compact});
  const std::uint64_t bytes = file_size(path);
  // The file reads back to every frame.
  std::uint64_t read = 0;
  {
    NativeTraceReader reader(path, /*max_frames=*/0);  // its own trace: no limit (the default stops at 10 M)
    TraceEvent e;
    while (reader.next(e)) read += e.kind == TraceEventKind::frame;
  }
  std::remove(path.c_str());
  if (read != frames) {
    state.SkipWithError("the recording does not read back to every frame");
    return;
  }
  state.SetLabel(std::string(gzip ? "gzip" : "plain") + (compact ? ", repeat lines" : ", a line per frame"));
  state.SetItemsProcessed(static_cast<std::int64_t>(frames) * state.iterations());
  state.counters["frames"] = static_cast<double>(frames);
  state.counters["file_bytes"] = static_cast<double>(bytes);
  state.counters["bytes_per_frame"] = static_cast<double>(bytes) / static_cast<double>(frames);
}
BENCHMARK(BM_RecordPollingHost)->DenseRange(0, 3)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

/// Replaying the minute of polling from its compacted file: the repetitions are expanded as read.
void BM_ReplayCompactPollingTrace(benchmark::State& state) {
  const std::string path = temp_path("poll-replay.trace");
  record_polling_host(path, NativeWriteOptions{false, true});
  ReplayResult r;
  for (auto _ : state) {
    NativeTraceReader reader(path, /*max_frames=*/0);  // its own trace: no limit (the default stops at 10 M)
    Chain chain(1);
    r = replay_trace(reader, chain);
  }
  std::remove(path.c_str());
  if (!r.matched()) {
    state.SkipWithError("the replay diverged from its own recording");
    return;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(r.frames) * state.iterations());
  state.counters["frames"] = static_cast<double>(r.frames);
}
BENCHMARK(BM_ReplayCompactPollingTrace)->Iterations(3)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
