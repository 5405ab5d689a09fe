// pthread_mutex_lock and pthread_mutex_unlock in virtual time: a lock that would block is a covered
// wait until the mutex is free, so that threads blocked on each other's mutexes (an ABBA deadlock)
// count as waiting and, with nothing else to wake them, are a deadlock naming each lock and its
// holder. The uncontended lock is one trylock; an unlock hands the mutex's first waiter its turn.
// Not covered (the C library's, and a thread blocked there counts as running): robust, priority-
// inheritance and priority-protected mutexes, timed locks, and the library's own locks.
#include <dlfcn.h>
#include <errno.h>
#include <link.h>
#include <pthread.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <string>

#include "linux/preload/real.hpp"
#include "linux/preload/virtual_time.hpp"

using namespace l6470emu;
using namespace l6470emu::preload;

namespace {

// glibc's struct __pthread_mutex_s __kind bits (nptl/pthreadP.h).
constexpr int kKindMask = 3;          // PTHREAD_MUTEX_KIND_MASK_NP
constexpr int kErrorCheck = 2;        // PTHREAD_MUTEX_ERRORCHECK_NP
constexpr int kRobust = 16;           // PTHREAD_MUTEX_ROBUST_NORMAL_NP
constexpr int kPrioInherit = 32;      // PTHREAD_MUTEX_PRIO_INHERIT_NP
constexpr int kPrioProtect = 64;      // PTHREAD_MUTEX_PRIO_PROTECT_NP
constexpr int kProcessShared = 128;   // PTHREAD_MUTEX_PSHARED_BIT

// A mutex unlocked where the library does not see it (inside the C library) is seen this often.
constexpr std::int64_t kMutexRecheckNs = 10'000'000;

// Threads in a covered mutex wait: an unlock looks for its waiter only when there is one.
std::atomic<int> g_mutex_waiters{0};
// The calling thread is handing a mutex on (the scheduler's own lock is unlocked meanwhile).
thread_local bool t_handing_on = false;

// The library's own code (its statically linked C++ runtime locks std::mutex through these
// functions too): its locks stay the C library's, or a covered wait would lock the scheduler's
// mutex inside itself.
struct LibraryText {
  std::uintptr_t begin = 0, end = 0;
};

int find_library_text(dl_phdr_info* info, std::size_t, void* data) {
  auto* text = static_cast<LibraryText*>(data);
  const auto self = reinterpret_cast<std::uintptr_t>(&find_library_text);
  for (int i = 0; i < info->dlpi_phnum; ++i) {
    const ElfW(Phdr)& ph = info->dlpi_phdr[i];
    if (ph.p_type != PT_LOAD || !(ph.p_flags & PF_X)) continue;
    const std::uintptr_t begin = info->dlpi_addr + ph.p_vaddr, end = begin + ph.p_memsz;
    if (self >= begin && self < end) {
      *text = {begin, end};
      return 1;
    }
  }
  return 0;
}

bool called_from_library(const void* return_address) {
  static const LibraryText text = [] {
    LibraryText t;
    dl_iterate_phdr(find_library_text, &t);
    return t;
  }();
  const auto at = reinterpret_cast<std::uintptr_t>(return_address);
  return at >= text.begin && at < text.end;
}

// Whether the lock of `m` may be a covered wait (a plain, recursive, error-checking or adaptive
// mutex), and not the error-checking mutex's own EDEADLK.
bool coverable(const pthread_mutex_t* m) {
  const int kind = m->__data.__kind;
  if (kind & (kRobust | kPrioInherit | kPrioProtect)) return false;
  return !((kind & kKindMask) == kErrorCheck && m->__data.__owner == ::gettid());
}

int lock_in_virtual_time(VirtualHostTime& vt, pthread_mutex_t* m) {
  VirtualScheduler::Wait w;
  w.call = "pthread_mutex_lock";
  w.object = m;
  w.outside = (m->__data.__kind & kProcessShared) != 0;  // another process may unlock it
  w.interruptible = false;  // a signal handler runs and the lock goes on waiting
  w.try_now = [m] { return real::pthread_mutex_trylock(m) == 0; };
  w.ready = w.try_now;
  w.recheck_ns = kMutexRecheckNs;
  w.describe = [m, self = ::gettid()] {
    char text[96];
    const int owner = m->__data.__owner;
    std::snprintf(text, sizeof text, "on the mutex at %p", static_cast<const void*>(m));
    return std::string(text) + (owner == self ? ", held by this thread itself"
                                : owner > 0   ? ", held by thread " + std::to_string(owner)
                                              : std::string());
  };
  g_mutex_waiters.fetch_add(1, std::memory_order_relaxed);
  struct Leave {
    ~Leave() { g_mutex_waiters.fetch_sub(1, std::memory_order_relaxed); }
  } leave;
  for (;;) {
    const VirtualScheduler::End end = vt.wait(w);
    if (end == VirtualScheduler::End::ready) return 0;  // try_now or ready took it
    // Notified (an unlock), or a pthread_cancel ended the wait (a lock is no cancellation point):
    // try again.
  }
}

}  // namespace

namespace l6470emu::preload {

int lock_program_mutex(VirtualHostTime& vt, pthread_mutex_t* m) {
  const int r = real::pthread_mutex_trylock(m);
  if (r != EBUSY || !coverable(m)) return r == EBUSY ? real::pthread_mutex_lock(m) : r;
  return lock_in_virtual_time(vt, m);
}

void mutex_waiters_after_fork_child() { g_mutex_waiters.store(0, std::memory_order_relaxed); }

void program_mutex_unlocked(pthread_mutex_t* m) {
  // No fence between the unlock and this load: a waiter that registered just now and is not
  // seen here is not lost for virtual time (its trylock, `ready`, runs before any jump), only
  // woken by its 10 ms look instead (on x86-64 the C library's unlock is a full barrier anyway).
  if (g_mutex_waiters.load(std::memory_order_relaxed) == 0 || t_handing_on) return;
  if (VirtualHostTime* vt = installed_virtual_time()) {
    t_handing_on = true;
    Guard guard;
    try {
      vt->scheduler().notify(m, false);
    } catch (...) {
    }
    t_handing_on = false;
  }
}

}  // namespace l6470emu::preload

extern "C" {

__attribute__((visibility("default"))) int pthread_mutex_lock(pthread_mutex_t* m) noexcept {
  VirtualHostTime* vt = virtual_time();
  if (!vt || is_null(m)) return real::pthread_mutex_lock(m);
  const int r = real::pthread_mutex_trylock(m);  // the uncontended lock: nothing more
  if (r != EBUSY) return r;
  if (called_from_library(__builtin_return_address(0))) return real::pthread_mutex_lock(m);
  Guard guard;
  try {
    return lock_program_mutex(*vt, m);
  } catch (...) {
    return real::pthread_mutex_lock(m);
  }
}

__attribute__((visibility("default"))) int pthread_mutex_unlock(pthread_mutex_t* m) noexcept {
  const int r = real::pthread_mutex_unlock(m);
  // The library's own mutexes have no covered waiters (its unlocks of a program's mutex, in a
  // condition variable's wait, call program_mutex_unlocked themselves).
  if (r == 0 && g_mutex_waiters.load(std::memory_order_relaxed) > 0 && !called_from_library(__builtin_return_address(0)))
    program_mutex_unlocked(m);
  return r;
}

}  // extern "C"
