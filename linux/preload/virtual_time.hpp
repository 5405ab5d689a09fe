// Virtual host time in the preload library (time=virtual, emulator in process): the program's
// clocks read the board's time and its waits are VirtualScheduler waits. What is not covered
// (vDSO-direct reads, raw system calls, POSIX timers, alarm) is listed in docs/linux.md.
#pragma once

#include <pthread.h>
#include <time.h>

#include <atomic>
#include <cstdint>
#include <string>

#include "board/board_config.hpp"
#include "linux/device_board.hpp"
#include "linux/preload/state.hpp"
#include "linux/virtual_scheduler.hpp"

namespace l6470emu::preload {

/// The kernel's largest time, KTIME_MAX (ns): a timeout that reaches it never ends, and no
/// virtual clock reads past it.
inline constexpr std::int64_t kKtimeMax = INT64_MAX;

/// Whether `ts` is a timespec the kernel takes (timespec64_valid: tv_sec >= 0, 0 <= tv_nsec < 10^9).
bool kernel_valid(const timespec& ts);
/// A valid `ts` in ns, saturated at kKtimeMax as the kernel's timespec64_to_ktime does.
std::int64_t saturated_ns(const timespec& ts);
/// a + b (both >= 0) saturated at kKtimeMax, as the kernel's ktime_add_safe.
std::int64_t add_saturated(std::int64_t a, std::int64_t b);

/// The process's virtual time: clock conversions, covered waits, the busy-wait rule, and the
/// board's wait for bus time.
///
/// Time ends where the kernel's does: every virtual clock (REALTIME and TAI, which read the
/// most, included) stays at most KTIME_MAX, so time never goes past last_tick() (about 236 years
/// after the program's start). A timeout that lies past it is no timeout (kNever), as a kernel
/// timer saturated at KTIME_MAX never fires; clocks saturate rather than wrap.
class VirtualHostTime {
 public:
  /// Makes `board`'s time the program's; `config` gives the idle grace. Counts the threads that
  /// exist already (/proc/self/task) as running.
  VirtualHostTime(DeviceBoard& board, const TimeConfig& config);
  ~VirtualHostTime();
  VirtualHostTime(const VirtualHostTime&) = delete;
  VirtualHostTime& operator=(const VirtualHostTime&) = delete;

  VirtualScheduler& scheduler() { return scheduler_; }

  /// Whether `clock` follows virtual time: the MONOTONIC, BOOTTIME, REALTIME and TAI families
  /// (CPU-time clocks stay real).
  static bool is_virtual_clock(clockid_t clock);
  /// What `clock` (a virtual one) reads now, ns.
  std::int64_t now_ns(clockid_t clock) const;
  /// What `clock` reads at `tick`, ns (at most kKtimeMax).
  std::int64_t ns_at(clockid_t clock, Tick tick) const;
  /// The first tick at which `clock` reads `ns` or later (an absolute deadline on that clock);
  /// kNever when that lies past last_tick().
  Tick tick_at(clockid_t clock, std::int64_t ns) const;
  /// The first tick at least `ns` from now (a relative timeout; <= 0 is now); kNever when that
  /// lies past last_tick().
  Tick tick_after(std::int64_t ns) const;
  /// The last tick at which every virtual clock reads at most KTIME_MAX.
  Tick last_tick() const { return last_tick_; }

  /// The tick of the first event queued on emulated line `fd` (kNever: none queued). The board
  /// stamps an edge a spidev message causes with the message's end, and queues it before the
  /// program's time gets there: a reader must not see it earlier than that tick.
  Tick first_event_tick(int fd) const;

  /// A covered wait of the calling thread (ends its busy-wait count).
  VirtualScheduler::End wait(const VirtualScheduler::Wait& w);
  /// A look at time that does not block (a clock read, a zero-length sleep, a zero-timeout poll,
  /// a gpio value read).
  /// After kSpinLooks of them in a row without a covered wait, each one first waits a quantum
  /// of virtual time: 1 µs, doubling every kLooksPerDoubling looks up to 1 ms. A thread spinning
  /// on the clock or on a pin lets time pass, deterministically, instead of hanging; a thread
  /// that merely reads the clock often is not disturbed below kSpinLooks.
  void look();
  /// The clock read just made belongs to a lock operation, not a look (CPython 3.11 reads the
  /// clock before every lock acquisition, then calls sem_trywait or a covered wait).
  void unlook();

  static constexpr std::int64_t kSpinLooks = 10'000;
  static constexpr std::int64_t kLooksPerDoubling = 1'000;
  static constexpr Tick kFirstQuantum = 4;      ///< 1 µs
  static constexpr Tick kLastQuantum = 4000;    ///< 1 ms

  /// fork(): the scheduler's lock is held across it; the child keeps one thread.
  void before_fork();
  void after_fork_parent();
  void after_fork_child();
  /// A campaign's snapshot child (fork_server.cpp): the one thread goes on as it was, with a
  /// wake-up descriptor of its own; its timer table is its own.
  void after_snapshot_fork_child();

 private:
  class BusWaiter final : public BoardTime::Waiter {
   public:
    explicit BusWaiter(VirtualHostTime& vt) : vt_(vt) {}
    void wait_until(Tick tick) override;

   private:
    VirtualHostTime& vt_;
  };

  std::int64_t offset_ns(clockid_t clock) const;
  VirtualScheduler::Hooks scheduler_hooks();
  std::string describe_fd(int fd) const;
  std::string describe_board();
  [[noreturn]] void end_deadlocked(const std::string& report);

  DeviceBoard& board_;
  BoardTime& time_;
  std::int64_t boottime_offset_ns_;  // real BOOTTIME - MONOTONIC at the start
  std::int64_t tai_offset_ns_;       // real TAI - REALTIME at the start
  Tick last_tick_;
  VirtualScheduler scheduler_;
  BusWaiter bus_waiter_{*this};
};

namespace detail {
extern std::atomic<VirtualHostTime*> g_virtual_time;
}

/// The process's virtual time, or nullptr in wall mode and for calls from inside the library:
/// the first thing every replaced time function checks (one atomic load in wall mode).
inline VirtualHostTime* virtual_time() {
  VirtualHostTime* vt = detail::g_virtual_time.load(std::memory_order_acquire);
  return vt && !inside() ? vt : nullptr;
}
/// The process's virtual time even from inside the library (nullptr in wall mode).
inline VirtualHostTime* installed_virtual_time() { return detail::g_virtual_time.load(std::memory_order_acquire); }

/// Whether `p` is null, for arguments glibc's headers declare nonnull (the compiler would drop
/// a plain test; a program may still pass NULL).
inline bool is_null(const void* p) {
  asm("" : "+r"(p));
  return p == nullptr;
}

/// Runs `body` (a covered wait, with its Guard and exception handling inside, never inlined) as
/// the C library's cancellation point it replaces: a pending pthread_cancel is acted on before
/// and after it, from the caller's frame, and held off while `body` runs (pthread_cancel ends a
/// covered wait instead). Forced unwinding must never cross the library's own frames: their
/// cleanups would run on the library's static copy of the unwinder, which aborts.
template <typename F>
[[gnu::always_inline]] inline auto as_cancellation_point(F&& body) {
  pthread_testcancel();
  int state = 0;
  pthread_setcancelstate(PTHREAD_CANCEL_DISABLE, &state);
  const auto r = body();
  pthread_setcancelstate(state, nullptr);
  pthread_testcancel();
  return r;
}

/// Makes `vt` the process's virtual time (LocalBackend, once).
void install_virtual_time(VirtualHostTime* vt);

// ---- hooks between the intercept_* files ----------------------------------------------

/// intercept_sync.cpp: thread accounting set up (the thread-exit key), and fork hooks of its table.
void init_thread_tracking();
void thread_table_before_fork();
void thread_table_after_fork();
/// intercept_timerfd.cpp: a virtual timer expired (the scheduler's fire hook).
void fire_virtual_timerfd(int fd);
/// intercept_timerfd.cpp: whether any virtual timerfd exists (cheap).
bool virtual_timerfds_exist();
/// intercept_timerfd.cpp: whether `fd` is a virtual timerfd (and, if so, whether it is armed).
bool is_virtual_timerfd(int fd, bool* armed = nullptr);
/// intercept_timerfd.cpp: read() of a virtual timerfd. False: `fd` is not one.
bool read_virtual_timerfd(int fd, void* buf, std::size_t count, ssize_t* result);
/// intercept_timerfd.cpp: `fd` was closed (or replaced by dup2): forget its timer.
void forget_virtual_timerfd(int fd);
void timerfd_table_before_fork();
void timerfd_table_after_fork();
/// intercept_timerfd.cpp: a snapshot's child owns the table (its lock was not taken for the fork).
void timerfd_table_after_snapshot();
/// intercept_mutex.cpp: locks a program's mutex as pthread_mutex_lock does, a covered wait when
/// it is held (from inside the library: a condition variable's wait taking its mutex again).
int lock_program_mutex(VirtualHostTime& vt, pthread_mutex_t* m);
/// intercept_mutex.cpp: a program's mutex `m` was unlocked: its first covered waiter tries again.
void program_mutex_unlocked(pthread_mutex_t* m);
/// intercept_mutex.cpp: fork()'s child has one thread, which waits on no mutex.
void mutex_waiters_after_fork_child();
/// intercept_poll.cpp: whether descriptor `fd` is an emulated gpio line with edge events.
bool is_emulated_line(int fd);

}  // namespace l6470emu::preload
