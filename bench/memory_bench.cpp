// Memory: sizeof(Chip) and what one chip of a chain costs (its Chip, its byte of the
// chain's shift register, its share of the Chain object), heap measured by counting
// every operator new of the process. A plain program: Google Benchmark is not linked.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <new>

#include "bench/heap_counter.hpp"
#include "core/chip.hpp"
#include "daisychain/chain.hpp"


namespace {

using namespace l6470emu;
using namespace l6470emu::bench;

constexpr double kGoalBytesPerChip = 1024.0;

struct ChainMemory {
  std::size_t chips;
  std::size_t heap_bytes;  ///< heap the chain still owns once built
  std::size_t peak_bytes;  ///< heap high-water mark while building it
  double per_chip() const { return static_cast<double>(sizeof(Chain) + heap_bytes) / static_cast<double>(chips); }
};

ChainMemory measure_chain(std::size_t n) {
  const std::size_t live_before = live_heap_bytes();
  reset_peak_heap_bytes();
  const Chain chain(n);
  return {chain.size(), live_heap_bytes() - live_before, peak_heap_bytes() - live_before};
}

}  // namespace

int main() {
  std::printf("l6470emu memory\n\n");
  std::printf("  sizeof(Chip)          %6zu bytes\n", sizeof(Chip));
  std::printf("    of which MotionState %5zu bytes, Profile %zu bytes, DiagnosticSink %zu bytes\n", sizeof(MotionState),
              sizeof(Profile), sizeof(DiagnosticSink));
  std::printf("  sizeof(Chain)         %6zu bytes\n", sizeof(Chain));
  const std::size_t before = live_heap_bytes();
  { const Chip chip; std::printf("  heap owned by a Chip  %6zu bytes\n\n", live_heap_bytes() - before); }

  std::printf("  %6s  %12s  %12s  %14s  %14s  %s\n", "chips", "heap bytes", "peak bytes", "bytes/chip", "expected*", "goal < 1 KiB");
  for (const std::size_t n : {std::size_t{1}, std::size_t{8}, std::size_t{64}, std::size_t{256}}) {
    const ChainMemory m = measure_chain(n);
    const double expected = static_cast<double>(sizeof(Chip) + 1) + static_cast<double>(sizeof(Chain)) / static_cast<double>(n);
    std::printf("  %6zu  %12zu  %12zu  %14.1f  %14.1f  %s\n", m.chips, m.heap_bytes, m.peak_bytes, m.per_chip(), expected,
                m.per_chip() < kGoalBytesPerChip ? "yes" : "NO");
  }
  std::printf("\n  * sizeof(Chip) + 1 shift-register byte + sizeof(Chain) / chips; bytes/chip is measured:\n"
              "    (sizeof(Chain) + heap the chain owns) / chips, heap counted through operator new.\n"
              "    peak: heap high-water mark while the chain is being built.\n");
  return 0;
}
