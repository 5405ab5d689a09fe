// timerfd on virtual clocks: an eventfd the scheduler writes when the timer expires (so poll,
// select and epoll see it), expirations worked out from virtual time. Not modelled: a dup() of it
// (reads as an eventfd), TFD_TIMER_CANCEL_ON_SET, TFD_IOC_SET_TICKS.
#include <errno.h>
#include <fcntl.h>
#include <sys/eventfd.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include <mutex>
#include <unordered_map>

#include "linux/preload/real.hpp"
#include "linux/preload/user_memory.hpp"
#include "linux/preload/virtual_time.hpp"

using namespace l6470emu;
using namespace l6470emu::preload;

namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;

struct VirtualTimer {
  clockid_t clock = CLOCK_MONOTONIC;
  std::int64_t expiry_ns = -1;   // next expiry on CLOCK_MONOTONIC (virtual), -1 = disarmed
  std::int64_t interval_ns = 0;  // 0 = one-shot
  bool signalled = false;        // the eventfd holds a count (the timer expired since the last read)
};

std::mutex g_mutex;
std::unordered_map<int, VirtualTimer>* g_timers = nullptr;  // never freed
std::atomic<int> g_count{0};                                // timers in the table (cheap "none" test)
std::atomic<pid_t> g_owner_pid{0};                          // the process the table belongs to

// Values as the kernel takes them (timerfd_settime: timespec64_valid, then saturated at KTIME_MAX).
bool valid(const timespec& ts) { return kernel_valid(ts); }
std::int64_t to_ns(const timespec& ts) { return saturated_ns(ts); }

timespec to_timespec(std::int64_t ns) {
  if (ns < 0) ns = 0;
  return {static_cast<time_t>(ns / kNsPerSecond), static_cast<long>(ns % kNsPerSecond)};
}

void drain(int fd, VirtualTimer& t) {
  if (!t.signalled) return;
  std::uint64_t v;
  [[maybe_unused]] const ssize_t n = real::read(fd, &v, sizeof v);  // holds a count: never blocks
  t.signalled = false;
}

void signal(int fd, VirtualTimer& t) {
  if (t.signalled) return;
  const std::uint64_t one = 1;
  [[maybe_unused]] const ssize_t n = real::write(fd, &one, sizeof one);
  t.signalled = true;
}

// Expirations of `t` up to `now` (monotonic ns), consumed: the timer moves to its next expiry.
std::uint64_t take_expirations(VirtualTimer& t, std::int64_t now) {
  if (t.expiry_ns < 0 || now < t.expiry_ns) return 0;
  if (t.interval_ns == 0) {
    t.expiry_ns = -1;
    return 1;
  }
  const std::uint64_t n = 1 + static_cast<std::uint64_t>((now - t.expiry_ns) / t.interval_ns);
  // The next expiry saturates at KTIME_MAX (hrtimer_forward's ktime_add_safe): never, not wrapped.
  const std::int64_t later = n > static_cast<std::uint64_t>(kKtimeMax / t.interval_ns)
                                 ? kKtimeMax
                                 : static_cast<std::int64_t>(n) * t.interval_ns;
  t.expiry_ns = add_saturated(t.expiry_ns, later);
  return n;
}

Tick tick_of(VirtualHostTime& vt, const VirtualTimer& t) {
  return t.expiry_ns < 0 ? kNever : vt.tick_at(CLOCK_MONOTONIC, t.expiry_ns);
}

itimerspec describe(VirtualHostTime& vt, const VirtualTimer& t) {
  itimerspec v{};
  v.it_interval = to_timespec(t.interval_ns);
  if (t.expiry_ns < 0) return v;
  const std::int64_t now = vt.now_ns(CLOCK_MONOTONIC);
  std::int64_t next = t.expiry_ns;
  if (now >= next && t.interval_ns > 0) next = add_saturated(next, ((now - next) / t.interval_ns + 1) * t.interval_ns);
  v.it_value = to_timespec(next > now ? next - now : 0);
  if (next <= now) v.it_value = {0, 1};  // expired one-shot not yet read: the kernel says "1 ns"
  return v;
}

}  // namespace

namespace l6470emu::preload {

void fire_virtual_timerfd(int fd) {
  VirtualHostTime* vt = installed_virtual_time();
  if (!vt) return;
  std::lock_guard lock(g_mutex);
  if (!g_timers) return;
  const auto it = g_timers->find(fd);
  if (it == g_timers->end()) return;
  VirtualTimer& t = it->second;
  if (t.expiry_ns >= 0 && t.expiry_ns <= vt->now_ns(CLOCK_MONOTONIC)) signal(fd, t);
}

bool virtual_timerfds_exist() { return g_count.load(std::memory_order_acquire) > 0; }

bool is_virtual_timerfd(int fd, bool* armed) {
  if (g_count.load(std::memory_order_acquire) == 0) return false;
  std::lock_guard lock(g_mutex);
  const auto it = g_timers->find(fd);
  if (it == g_timers->end()) return false;
  if (armed) *armed = it->second.expiry_ns >= 0;
  return true;
}

bool read_virtual_timerfd(int fd, void* buf, std::size_t count, ssize_t* result) {
  if (g_count.load(std::memory_order_acquire) == 0) return false;
  VirtualHostTime* vt = virtual_time();
  if (!vt) return false;
  Guard guard;
  for (;;) {
    Tick wake = kNever;
    std::uint64_t n = 0;
    {
      std::lock_guard lock(g_mutex);
      const auto it = g_timers->find(fd);
      if (it == g_timers->end()) return false;
      if (count < sizeof(std::uint64_t)) {
        errno = EINVAL;
        *result = -1;
        return true;
      }
      VirtualTimer& t = it->second;
      n = take_expirations(t, vt->now_ns(CLOCK_MONOTONIC));
      if (n > 0) {
        drain(fd, t);
        wake = tick_of(*vt, t);
      } else if (real::fcntl(fd, F_GETFL, 0) & O_NONBLOCK) {
        errno = EAGAIN;
        *result = -1;
        return true;
      } else {
        wake = tick_of(*vt, t);
      }
    }
    if (n > 0) {
      // Outside the table's lock: the scheduler takes the table's lock when it fires a timer.
      vt->scheduler().set_timer(fd, wake);
      if (!copy_to_user(buf, &n, sizeof n)) {
        errno = EFAULT;
        *result = -1;
        return true;
      }
      *result = sizeof n;
      return true;
    }
    const pollfd p{fd, POLLIN, 0};  // re-armed to expire at once by another thread
    VirtualScheduler::Wait w;
    w.call = "read";
    w.deadline = wake;
    w.fds = std::span<const pollfd>(&p, 1);
    if (vt->wait(w) == VirtualScheduler::End::interrupted) {
      errno = EINTR;
      *result = -1;
      return true;
    }
  }
}

void forget_virtual_timerfd(int fd) {
  if (g_count.load(std::memory_order_acquire) == 0) return;
  // A vfork()ed child (posix_spawn, CPython's subprocess) closes descriptors before exec in its
  // parent's memory: the parent's timers are not its to forget. (A fork()ed child has its own
  // copy, and the fork handlers made it the owner.)
  if (getpid() != g_owner_pid.load(std::memory_order_acquire)) return;
  bool found = false;
  {
    std::lock_guard lock(g_mutex);
    found = g_timers->erase(fd) > 0;
    if (found) g_count.fetch_sub(1, std::memory_order_acq_rel);
  }
  if (!found) return;
  if (VirtualHostTime* vt = installed_virtual_time()) {
    Guard guard;
    vt->scheduler().set_timer(fd, kNever);
  }
}

void timerfd_table_before_fork() { g_mutex.lock(); }
void timerfd_table_after_snapshot() { g_owner_pid.store(getpid(), std::memory_order_release); }

void timerfd_table_after_fork() {
  g_owner_pid.store(getpid(), std::memory_order_release);
  g_mutex.unlock();
}

}  // namespace l6470emu::preload

extern "C" {

__attribute__((visibility("default"))) int timerfd_create(int clock, int flags) noexcept {
  VirtualHostTime* vt = virtual_time();
  if (!vt || (clock != CLOCK_MONOTONIC && clock != CLOCK_REALTIME && clock != CLOCK_BOOTTIME &&
              clock != CLOCK_REALTIME_ALARM && clock != CLOCK_BOOTTIME_ALARM))
    return real::timerfd_create(clock, flags);
  if (flags & ~(TFD_CLOEXEC | TFD_NONBLOCK)) {
    errno = EINVAL;
    return -1;
  }
  Guard guard;
  try {
    std::lock_guard lock(g_mutex);
    if (!g_timers) {
      g_timers = new std::unordered_map<int, VirtualTimer>();
      g_owner_pid.store(getpid(), std::memory_order_release);
    }
    const int fd = eventfd(0, flags);  // TFD_CLOEXEC == EFD_CLOEXEC, TFD_NONBLOCK == EFD_NONBLOCK
    if (fd < 0) return -1;
    VirtualTimer t;
    t.clock = clock;
    if (g_timers->insert_or_assign(fd, t).second) g_count.fetch_add(1, std::memory_order_acq_rel);
    return fd;
  } catch (...) {
    return real::timerfd_create(clock, flags);
  }
}

__attribute__((visibility("default"))) int timerfd_settime(int fd, int flags, const struct itimerspec* value,
                                                           struct itimerspec* old) noexcept {
  VirtualHostTime* vt = virtual_time();
  if (!vt || g_count.load(std::memory_order_acquire) == 0) return real::timerfd_settime(fd, flags, value, old);
  Guard guard;
  std::unique_lock lock(g_mutex);
  const auto it = g_timers->find(fd);
  if (it == g_timers->end()) {
    lock.unlock();
    return real::timerfd_settime(fd, flags, value, old);
  }
  if (!value || !valid(value->it_value) || !valid(value->it_interval) ||
      (flags & ~(TFD_TIMER_ABSTIME | TFD_TIMER_CANCEL_ON_SET))) {
    errno = value ? EINVAL : EFAULT;
    return -1;
  }
  VirtualTimer& t = it->second;
  if (old) *old = describe(*vt, t);
  drain(fd, t);  // setting the timer resets its expiration count
  t.interval_ns = to_ns(value->it_interval);
  const std::int64_t v = to_ns(value->it_value);
  if (v == 0) {
    t.expiry_ns = -1;
  } else if (flags & TFD_TIMER_ABSTIME) {
    // On the timer's clock, as MONOTONIC: a time past the end of the clock is KTIME_MAX (never).
    const std::int64_t now_clock = vt->now_ns(t.clock);
    const std::int64_t now_mono = vt->now_ns(CLOCK_MONOTONIC);
    t.expiry_ns = v >= now_clock ? add_saturated(now_mono, v - now_clock) : std::max<std::int64_t>(0, now_mono - (now_clock - v));
  } else {
    t.expiry_ns = add_saturated(vt->now_ns(CLOCK_MONOTONIC), v);
  }
  Tick next = tick_of(*vt, t);
  if (t.expiry_ns >= 0 && t.expiry_ns <= vt->now_ns(CLOCK_MONOTONIC)) {
    signal(fd, t);  // already due (an absolute time in the past)
    next = kNever;
  }
  lock.unlock();  // the scheduler takes the table's lock when it fires a timer
  vt->scheduler().set_timer(fd, next);
  return 0;
}

__attribute__((visibility("default"))) int timerfd_gettime(int fd, struct itimerspec* value) noexcept {
  VirtualHostTime* vt = virtual_time();
  if (!vt || g_count.load(std::memory_order_acquire) == 0) return real::timerfd_gettime(fd, value);
  Guard guard;
  std::lock_guard lock(g_mutex);
  const auto it = g_timers->find(fd);
  if (it == g_timers->end()) return real::timerfd_gettime(fd, value);
  if (!value) {
    errno = EFAULT;
    return -1;
  }
  *value = describe(*vt, it->second);
  return 0;
}

}  // extern "C"
