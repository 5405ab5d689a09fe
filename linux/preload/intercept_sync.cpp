// pthread_create/join, condition variables and semaphores for virtual time: threads counted, waits
// with virtual timeouts, signal/post handed to the first waiter. Mutexes: intercept_mutex.cpp. Not
// virtualised: rwlocks, objects shared with another process. Wall mode: the C library's.
#include <errno.h>
#include <pthread.h>
#include <semaphore.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <new>
#include <unordered_map>

#include "linux/preload/real.hpp"
#include "linux/preload/virtual_time.hpp"

using namespace l6470emu;
using namespace l6470emu::preload;
using End = VirtualScheduler::End;

namespace {

// A semaphore posted from another process is seen this often (a post in this process is handed
// over at once).
constexpr std::int64_t kSemaphoreRecheckNs = 10'000'000;

// An absolute timeout as glibc takes it: tv_nsec outside [0, 10^9) is EINVAL, a negative tv_sec
// has passed already (ETIMEDOUT), a time past KTIME_MAX saturates there (it never comes).
bool valid(const timespec& ts) { return ts.tv_nsec >= 0 && ts.tv_nsec < 1'000'000'000; }
std::int64_t to_ns(const timespec& ts) { return ts.tv_sec < 0 ? -1 : saturated_ns(ts); }

// Whether another process may post the semaphore: glibc (struct new_sem on 64-bit targets)
// keeps the futex flag after the 64-bit value: 0 for a process-private semaphore, FUTEX_PRIVATE_FLAG
// (128) for one shared between processes (sem_init with pshared, sem_open).
bool shared_semaphore(const sem_t* s) {
  int flag = 0;
  std::memcpy(&flag, reinterpret_cast<const char*>(s) + sizeof(std::uint64_t), sizeof flag);
  return flag != 0;
}

// Whether another process may signal the condition variable: bit 0 of __wrefs (glibc >= 2.25).
bool shared_cond(const pthread_cond_t* c) { return (c->__data.__wrefs & 1) != 0; }

// ---- threads --------------------------------------------------------------------------

// What a joiner waits on: the thread's exit, seen by its thread-exit key destructor.
struct Joinable {
  std::atomic<bool> exited{false};
  std::atomic<pid_t> tid{0};  // the thread's id, once it runs (for the deadlock report)
};

struct Start {
  void* (*fn)(void*);
  void* arg;
  bool internal;  // created by the library itself: runs inside, uncounted
  std::shared_ptr<Joinable> joinable;
};

pthread_key_t g_exit_key;
std::once_flag g_key_once;
std::mutex g_threads_mutex;
std::unordered_map<pthread_t, std::shared_ptr<Joinable>>* g_threads = nullptr;  // never freed

void thread_exiting(void* value) {
  auto* joinable = static_cast<std::shared_ptr<Joinable>*>(value);
  if (VirtualHostTime* vt = installed_virtual_time()) {
    Guard guard;
    (*joinable)->exited.store(true, std::memory_order_release);
    try {
      vt->scheduler().thread_exited(joinable->get());
    } catch (...) {
    }
  }
  delete joinable;
  // Whatever this thread still runs (other keys' destructors) is no longer counted: let it
  // reach the C library directly.
  alignas(Guard) static thread_local unsigned char rest_inside[sizeof(Guard)];
  new (rest_inside) Guard;
}

void* start_thread(void* p) {
  Start* s = static_cast<Start*>(p);
  void* (*fn)(void*) = s->fn;
  void* arg = s->arg;
  if (s->internal) {
    delete s;
    Guard guard;
    return fn(arg);
  }
  s->joinable->tid.store(::gettid(), std::memory_order_release);
  pthread_setspecific(g_exit_key, new std::shared_ptr<Joinable>(std::move(s->joinable)));
  delete s;
  return fn(arg);
}

// ---- condition variables ----------------------------------------------------------------

// The clock a condition variable's timed waits use: glibc (since 2.25) keeps the clock chosen with
// pthread_condattr_setclock in bit 1 of __wrefs, set at initialisation and never changed.
clockid_t cond_clock(const pthread_cond_t* c) {
  return (c->__data.__wrefs & 2) ? CLOCK_MONOTONIC : CLOCK_REALTIME;
}

// A wait that never touches the C library's condition variable: the mutex is released once the
// scheduler has registered the waiter (a signal after that cannot be lost) and taken again after.
int cond_wait(VirtualHostTime& vt, pthread_cond_t* c, pthread_mutex_t* m, clockid_t clock, const timespec* abstime,
              const char* call) {
  VirtualScheduler::Wait w;
  w.call = call;
  w.object = c;
  w.outside = shared_cond(c);
  w.interruptible = false;  // a signal handler runs and the wait goes on (a spurious wake-up is allowed)
  if (abstime) {
    if (!valid(*abstime)) return EINVAL;
    w.deadline = vt.tick_at(clock, to_ns(*abstime));
    w.timeout_beyond_end = w.deadline == kNever;
  }
  int unlock_error = 0;
  bool unlocked = false;
  w.after_register = [&] {
    unlock_error = pthread_mutex_unlock(m);
    unlocked = unlock_error == 0;
    if (unlocked) program_mutex_unlocked(m);
    return unlocked;
  };
  const End end = vt.wait(w);
  if (unlock_error) return unlock_error;  // not the caller's mutex (error-checking types)
  if (unlocked) {
    const int r = lock_program_mutex(vt, m);
    if (r != 0) return r;  // EOWNERDEAD of a robust mutex
  }
  return end == End::timed_out ? ETIMEDOUT : 0;
}

// ---- semaphores -------------------------------------------------------------------------

// 0, or -1 with errno, as sem_wait does.
int sem_wait_virtual(VirtualHostTime& vt, sem_t* s, clockid_t clock, const timespec* abstime, const char* call) {
  VirtualScheduler::Wait w;
  w.call = call;
  w.object = s;
  w.outside = shared_semaphore(s);
  w.try_now = [s] {
    const int saved = errno;
    const bool taken = real::sem_trywait(s) == 0;
    errno = saved;
    return taken;
  };
  w.ready = w.try_now;
  w.recheck_ns = kSemaphoreRecheckNs;
  if (abstime) {
    if (!valid(*abstime)) {
      if (w.try_now()) return 0;
      errno = EINVAL;
      return -1;
    }
    w.deadline = vt.tick_at(clock, to_ns(*abstime));
    w.timeout_beyond_end = w.deadline == kNever;
  }
  switch (vt.wait(w)) {
    case End::ready:
    case End::notified:
      return 0;
    case End::timed_out:
      errno = ETIMEDOUT;
      return -1;
    default:
      errno = EINTR;
      return -1;
  }
}

}  // namespace

namespace l6470emu::preload {

void init_thread_tracking() {
  std::call_once(g_key_once, [] {
    g_threads = new std::unordered_map<pthread_t, std::shared_ptr<Joinable>>();
    pthread_key_create(&g_exit_key, thread_exiting);
  });
}

void thread_table_before_fork() { g_threads_mutex.lock(); }
void thread_table_after_fork() { g_threads_mutex.unlock(); }

}  // namespace l6470emu::preload

extern "C" {

__attribute__((visibility("default"))) int pthread_create(pthread_t* t, const pthread_attr_t* attr, void* (*fn)(void*),
                                                          void* arg) noexcept {
  VirtualHostTime* vt = installed_virtual_time();
  if (!vt || is_null(t)) return real::pthread_create(t, attr, fn, arg);
  const bool internal = inside();
  Guard guard;
  Start* s = new (std::nothrow) Start{fn, arg, internal, nullptr};
  if (!s) return EAGAIN;
  std::shared_ptr<Joinable> joinable;
  try {
    if (!internal) s->joinable = joinable = std::make_shared<Joinable>();
  } catch (...) {
    delete s;
    return EAGAIN;
  }
  // Counted as running from before it exists: nothing can jump between its creation and its start.
  if (!internal) vt->scheduler().thread_started();
  const int r = real::pthread_create(t, attr, start_thread, s);
  if (r != 0) {
    delete s;
    if (!internal) vt->scheduler().thread_not_started();
    return r;
  }
  if (!internal) {
    std::lock_guard lock(g_threads_mutex);
    try {
      (*g_threads)[*t] = std::move(joinable);
    } catch (...) {
    }
  }
  return 0;
}

__attribute__((visibility("default"))) int pthread_join(pthread_t t, void** result) {
  VirtualHostTime* vt = virtual_time();
  if (!vt) return real::pthread_join(t, result);
  // A cancellation of the joining thread is acted on once the joined thread has ended.
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    std::shared_ptr<Joinable> joinable;
    {
      std::lock_guard lock(g_threads_mutex);
      if (const auto it = g_threads->find(t); it != g_threads->end()) {
        joinable = std::move(it->second);
        g_threads->erase(it);
      }
    }
    if (!joinable) return real::pthread_join(t, result);  // a thread the library did not see start
    int r = 0;
    try {
      VirtualScheduler::Wait w;
      w.call = "pthread_join";
      w.object = joinable.get();
      w.joined_tid = &joinable->tid;
      w.try_now = [&] { return joinable->exited.load(std::memory_order_acquire); };
      vt->scheduler().wait_in(w, [&] { r = real::pthread_join(t, result); });
    } catch (...) {
      r = real::pthread_join(t, result);
    }
    return r;
  });
}

// As glibc declares it: without __THROW (no noexcept), so that clang accepts the definition.
__attribute__((visibility("default"))) int pthread_cancel(pthread_t t) {
  const int r = real::pthread_cancel(t);
  // A covered wait holds cancellation off (the library's own frames cannot be unwound): end the
  // thread's wait, so that it acts on the request as it leaves.
  if (r == 0)
    if (VirtualHostTime* vt = virtual_time()) {
      Guard guard;
      try {
        vt->scheduler().interrupt(t);
      } catch (...) {
      }
    }
  return r;
}

__attribute__((visibility("default"))) int pthread_cond_wait(pthread_cond_t* c, pthread_mutex_t* m) {
  VirtualHostTime* vt = virtual_time();
  if (!vt) return real::pthread_cond_wait(c, m);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return cond_wait(*vt, c, m, CLOCK_REALTIME, nullptr, "pthread_cond_wait");
    } catch (...) {
      return real::pthread_cond_wait(c, m);
    }
  });
}

__attribute__((visibility("default"))) int pthread_cond_timedwait(pthread_cond_t* c, pthread_mutex_t* m,
                                                                  const struct timespec* abstime) {
  VirtualHostTime* vt = virtual_time();
  if (!vt || is_null(abstime)) return real::pthread_cond_timedwait(c, m, abstime);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return cond_wait(*vt, c, m, cond_clock(c), abstime, "pthread_cond_timedwait");
    } catch (...) {
      return real::pthread_cond_timedwait(c, m, abstime);
    }
  });
}

__attribute__((visibility("default"))) int pthread_cond_clockwait(pthread_cond_t* c, pthread_mutex_t* m, clockid_t clock,
                                                                  const struct timespec* abstime) {
  VirtualHostTime* vt = virtual_time();
  if (!vt || is_null(abstime) || (clock != CLOCK_MONOTONIC && clock != CLOCK_REALTIME))
    return real::pthread_cond_clockwait(c, m, clock, abstime);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return cond_wait(*vt, c, m, clock, abstime, "pthread_cond_clockwait");
    } catch (...) {
      return real::pthread_cond_clockwait(c, m, clock, abstime);
    }
  });
}

__attribute__((visibility("default"))) int pthread_cond_signal(pthread_cond_t* c) noexcept {
  if (VirtualHostTime* vt = virtual_time()) {
    Guard guard;
    try {
      vt->scheduler().notify(c, false);
    } catch (...) {
    }
  }
  return real::pthread_cond_signal(c);  // for waits that began inside the library or before it
}

__attribute__((visibility("default"))) int pthread_cond_broadcast(pthread_cond_t* c) noexcept {
  if (VirtualHostTime* vt = virtual_time()) {
    Guard guard;
    try {
      vt->scheduler().notify(c, true);
    } catch (...) {
    }
  }
  return real::pthread_cond_broadcast(c);
}

__attribute__((visibility("default"))) int sem_wait(sem_t* s) {
  VirtualHostTime* vt = virtual_time();
  if (!vt) return real::sem_wait(s);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return sem_wait_virtual(*vt, s, CLOCK_REALTIME, nullptr, "sem_wait");
    } catch (...) {
      return real::sem_wait(s);
    }
  });
}

__attribute__((visibility("default"))) int sem_timedwait(sem_t* s, const struct timespec* abstime) {
  VirtualHostTime* vt = virtual_time();
  if (!vt || is_null(abstime)) return real::sem_timedwait(s, abstime);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return sem_wait_virtual(*vt, s, CLOCK_REALTIME, abstime, "sem_timedwait");
    } catch (...) {
      return real::sem_timedwait(s, abstime);
    }
  });
}

__attribute__((visibility("default"))) int sem_clockwait(sem_t* s, clockid_t clock, const struct timespec* abstime) {
  VirtualHostTime* vt = virtual_time();
  if (!vt || is_null(abstime) || (clock != CLOCK_MONOTONIC && clock != CLOCK_REALTIME))
    return real::sem_clockwait(s, clock, abstime);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return sem_wait_virtual(*vt, s, clock, abstime, "sem_clockwait");
    } catch (...) {
      return real::sem_clockwait(s, clock, abstime);
    }
  });
}

// Not a wait: only the busy-wait rule's count learns that the clock read before it was part of
// a lock acquisition (CPython), not a look at the time.
__attribute__((visibility("default"))) int sem_trywait(sem_t* s) noexcept {
  if (VirtualHostTime* vt = virtual_time()) vt->unlook();
  return real::sem_trywait(s);
}

__attribute__((visibility("default"))) int sem_post(sem_t* s) noexcept {
  VirtualHostTime* vt = virtual_time();
  if (!vt) return real::sem_post(s);
  Guard guard;
  try {
    if (vt->scheduler().grant(s)) return 0;
  } catch (...) {
  }
  return real::sem_post(s);
}

}  // extern "C"
