// Replacement global operator new/delete that count requested bytes (single-threaded programs).
#include "bench/heap_counter.hpp"

#include <cstdlib>
#include <new>

namespace {

std::size_t g_live_bytes = 0;  // requested bytes currently allocated
std::size_t g_peak_bytes = 0;  // high-water mark of g_live_bytes
constexpr std::size_t kHeader = alignof(std::max_align_t);  // keeps the size in front of the block

void* counted_alloc(std::size_t n) {
  void* raw = std::malloc(n + kHeader);
  if (raw == nullptr) throw std::bad_alloc();
  *static_cast<std::size_t*>(raw) = n;
  g_live_bytes += n;
  if (g_live_bytes > g_peak_bytes) g_peak_bytes = g_live_bytes;
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

namespace l6470emu::bench {

std::size_t live_heap_bytes() { return g_live_bytes; }
std::size_t peak_heap_bytes() { return g_peak_bytes; }
void reset_peak_heap_bytes() { g_peak_bytes = g_live_bytes; }

}  // namespace l6470emu::bench
