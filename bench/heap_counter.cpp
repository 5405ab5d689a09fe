// Replacement global operator new/delete that count requested bytes (single-threaded programs).
#include "bench/heap_counter.hpp"

#include <algorithm>
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

// Over-aligned types (Chip is aligned to a cache line): the header takes a whole alignment unit.
void* counted_alloc(std::size_t n, std::align_val_t al) {
  const std::size_t a = std::max(static_cast<std::size_t>(al), kHeader);
  void* raw = std::aligned_alloc(a, (n + a + a - 1) / a * a);
  if (raw == nullptr) throw std::bad_alloc();
  *static_cast<std::size_t*>(raw) = n;
  g_live_bytes += n;
  if (g_live_bytes > g_peak_bytes) g_peak_bytes = g_live_bytes;
  return static_cast<char*>(raw) + a;
}

void counted_free(void* p, std::align_val_t al) noexcept {
  if (p == nullptr) return;
  char* raw = static_cast<char*>(p) - std::max(static_cast<std::size_t>(al), kHeader);
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
void* operator new(std::size_t n, std::align_val_t al) { return counted_alloc(n, al); }
void* operator new[](std::size_t n, std::align_val_t al) { return counted_alloc(n, al); }
void operator delete(void* p, std::align_val_t al) noexcept { counted_free(p, al); }
void operator delete[](void* p, std::align_val_t al) noexcept { counted_free(p, al); }
void operator delete(void* p, std::size_t, std::align_val_t al) noexcept { counted_free(p, al); }
void operator delete[](void* p, std::size_t, std::align_val_t al) noexcept { counted_free(p, al); }

namespace l6470emu::bench {

std::size_t live_heap_bytes() { return g_live_bytes; }
std::size_t peak_heap_bytes() { return g_peak_bytes; }
void reset_peak_heap_bytes() { g_peak_bytes = g_live_bytes; }

}  // namespace l6470emu::bench
