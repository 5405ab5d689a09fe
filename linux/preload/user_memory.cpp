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

/// One checked copy: `user` is the host program's side (read from or written to), `vm_copy`
/// the process_vm_readv/writev call that faults cleanly instead of crashing. Pages that
/// copied fine once are remembered so hot buffers cost a plain memcpy.
template <class VmCopy>
bool checked_copy(void* dst, const void* src, std::size_t n, const void* user, std::uintptr_t* seen, VmCopy vm_copy) {
  if (n == 0) return true;
  const auto a = reinterpret_cast<std::uintptr_t>(user);
  if (a < kPage || a + n < a) return false;
  const std::uintptr_t first = a / kPage, last = (a + n - 1) / kPage;
  if ((last - first < 8 && known(seen, first, last)) || g_vm_unsupported.load(std::memory_order_relaxed)) {
    std::memcpy(dst, src, n);
    return true;
  }
  iovec local{const_cast<void*>(user == src ? dst : src), n}, remote{const_cast<void*>(user), n};
  const int saved = errno;
  const ssize_t r = vm_copy(&local, &remote);
  if (r == static_cast<ssize_t>(n)) {
    remember(seen, first, last);
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

}  // namespace

bool copy_from_user(void* dst, const void* src, std::size_t n) {
  return checked_copy(dst, src, n, src, cache().read,
                      [](iovec* local, iovec* remote) { return process_vm_readv(getpid(), local, 1, remote, 1, 0); });
}

bool copy_to_user(void* dst, const void* src, std::size_t n) {
  return checked_copy(dst, src, n, dst, cache().write,
                      [](iovec* local, iovec* remote) { return process_vm_writev(getpid(), local, 1, remote, 1, 0); });
}

void forget_user_pages() { g_generation.fetch_add(1, std::memory_order_relaxed); }

}  // namespace l6470emu::preload
