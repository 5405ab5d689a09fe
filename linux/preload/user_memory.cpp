// EFAULT-faithful user memory copies.
#include "linux/preload/user_memory.hpp"

#include <sys/uio.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstring>

namespace l6470emu::preload {
namespace {

constexpr std::size_t kPage = 4096;
constexpr std::size_t kSlots = 256;

struct PageCache {
  std::uintptr_t read[kSlots] = {};
  std::uintptr_t write[kSlots] = {};
  unsigned generation = 0;
};
thread_local PageCache t_cache __attribute__((tls_model("initial-exec")));
std::atomic<unsigned> g_generation{1};
std::atomic<int> g_vm_unsupported{0};  // process_vm_* refused (seccomp, old kernel): trust pointers

bool known(const std::uintptr_t* slots, std::uintptr_t first, std::uintptr_t last) {
  for (std::uintptr_t p = first; p <= last; ++p)
    if (slots[p % kSlots] != p) return false;
  return true;
}
void remember(std::uintptr_t* slots, std::uintptr_t first, std::uintptr_t last) {
  for (std::uintptr_t p = first; p <= last; ++p) slots[p % kSlots] = p;
}

PageCache& cache() {
  const unsigned g = g_generation.load(std::memory_order_relaxed);
  if (t_cache.generation != g) {
    std::memset(t_cache.read, 0, sizeof t_cache.read);
    std::memset(t_cache.write, 0, sizeof t_cache.write);
    t_cache.generation = g;
  }
  return t_cache;
}

}  // namespace

bool copy_from_user(void* dst, const void* src, std::size_t n) {
  if (n == 0) return true;
  const auto a = reinterpret_cast<std::uintptr_t>(src);
  if (a < kPage || a + n < a) return false;
  const std::uintptr_t first = a / kPage, last = (a + n - 1) / kPage;
  PageCache& c = cache();
  if (last - first < 8 && known(c.read, first, last)) {
    std::memcpy(dst, src, n);
    return true;
  }
  if (g_vm_unsupported.load(std::memory_order_relaxed)) {
    std::memcpy(dst, src, n);
    return true;
  }
  iovec local{dst, n}, remote{const_cast<void*>(src), n};
  const int saved = errno;
  const ssize_t r = process_vm_readv(getpid(), &local, 1, &remote, 1, 0);
  if (r == static_cast<ssize_t>(n)) {
    remember(c.read, first, last);
    errno = saved;
    return true;
  }
  if (r < 0 && (errno == ENOSYS || errno == EPERM)) {
    g_vm_unsupported.store(1);
    errno = saved;
    std::memcpy(dst, src, n);
    return true;
  }
  errno = saved;
  return false;
}

bool copy_to_user(void* dst, const void* src, std::size_t n) {
  if (n == 0) return true;
  const auto a = reinterpret_cast<std::uintptr_t>(dst);
  if (a < kPage || a + n < a) return false;
  const std::uintptr_t first = a / kPage, last = (a + n - 1) / kPage;
  PageCache& c = cache();
  if (last - first < 8 && known(c.write, first, last)) {
    std::memcpy(dst, src, n);
    return true;
  }
  if (g_vm_unsupported.load(std::memory_order_relaxed)) {
    std::memcpy(dst, src, n);
    return true;
  }
  iovec local{const_cast<void*>(src), n}, remote{dst, n};
  const int saved = errno;
  const ssize_t r = process_vm_writev(getpid(), &local, 1, &remote, 1, 0);
  if (r == static_cast<ssize_t>(n)) {
    remember(c.write, first, last);
    errno = saved;
    return true;
  }
  if (r < 0 && (errno == ENOSYS || errno == EPERM)) {
    g_vm_unsupported.store(1);
    errno = saved;
    std::memcpy(dst, src, n);
    return true;
  }
  errno = saved;
  return false;
}

void forget_user_pages() { g_generation.fetch_add(1, std::memory_order_relaxed); }

}  // namespace l6470emu::preload
