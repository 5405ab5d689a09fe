// The scheduler of virtual host time: which threads wait in a covered wait and, when all do, the
// jump of virtual time to the earliest wake-up (Go's testing/synctest rule). Interposes nothing.
#pragma once

#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/types.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/tick.hpp"

namespace l6470emu {

/// The exit status of a program that virtual time found deadlocked: every thread waits in a
/// covered call and nothing can ever wake any of them (see VirtualScheduler). Distinct from the
/// statuses programs and tools commonly use (0-5, 23, 64-78, 99, 124-127, 128 + a signal) and
/// from the driver sanitizer's 86 (board/check_rules.hpp), so a plain program's status says which.
inline constexpr int kDeadlockExitStatus = 87;

/// Virtual time for the threads of one process.
///
/// Every thread of the program is either *running* or *waiting* in a covered wait. Virtual time
/// moves only when every thread waits: then it jumps to the earliest wake-up (a waiter's deadline,
/// an armed timer, or, when a waiter watches the board's lines, the board's next edge), the board
/// is brought there (edges delivered), and exactly the waiters due are woken. A woken thread counts
/// as running from the moment of that decision, not from when it gets a CPU, so the outcome does
/// not depend on the host's scheduler. In-process hand-offs (notify() for condition variables and
/// joins, grant() for semaphores, descriptors made ready by another thread, checked with a
/// zero-timeout poll before any jump) end waits without moving time.
///
/// A thread that is neither running covered code nor waiting (blocked in a call the preload does
/// not see) stalls time; after `idle_ns` of real time without any wait entered or left, time moves
/// on anyway to the earliest wake-up, and that is logged once (the run may not repeat exactly).
///
/// A deadlock is what virtual time can see and real time cannot: every thread waits, none has a
/// wake-up to come (no deadline, no armed timer, no edge on a line a waiter watches), none waits
/// on anything another process could end (a descriptor that is not an emulated line or virtual
/// timer, a process-shared semaphore or condition variable), and no real timer (alarm, setitimer,
/// timer_create) is armed to send a signal. Then Hooks::deadlock gets a report of what each thread
/// waits on (it ends the process with kDeadlockExitStatus); a thread outside the covered calls
/// counts as running, so a deadlock is never declared while one exists.
class VirtualScheduler {
 public:
  /// What the scheduler drives and reads. `now` and `advance_to` are required.
  struct Hooks {
    std::function<Tick()> now;               ///< the board's tick
    std::function<void(Tick)> advance_to;    ///< moves the board to a tick (edges delivered)
    std::function<Tick()> next_edge;         ///< the board's next edge on a watched line (kNever: none)
    /// The world's next change whatever the threads wait for (a scenario's next step, a run's
    /// time limit; kNever: none): always a wake-up, so never a deadlock while one is to come.
    std::function<Tick()> next_world;
    /// The run's time limit (kNever: none): the clocks jump there when every thread waits for
    /// it alone, but only once the waits were found to be no deadlock (a thread that nothing but
    /// the limit can wake is deadlocked, limit or not), and not while a thread waits on another
    /// process (a child, a pipe's writer) or an armed real timer, which go on in real time meanwhile.
    std::function<Tick()> time_limit;
    std::function<void(int)> fire_timer;     ///< a timer set with set_timer() expired
    std::function<std::int64_t()> real_ns;   ///< the real monotonic clock, ns (idle grace)
    std::function<void(std::string_view)> log;  ///< diagnostics (the idle-grace line)
    /// Whether descriptor `fd` becomes ready only through this process (an emulated gpio line, a
    /// virtual timerfd). Unset: every descriptor may be made ready from outside (no deadlock).
    std::function<bool(int fd)> inside_fd;
    /// Words for a descriptor in the deadlock report ("fd 5, a gpio line request on /dev/gpiochip0").
    std::function<std::string(int fd)> describe_fd;
    /// Why a signal may still come from outside the covered calls (an armed alarm), or "".
    std::function<std::string()> outside_wakeup;
    /// The board's side of the deadlock report (lines watched, their levels), or "".
    std::function<std::string()> describe_board;
    /// A deadlock was found (the scheduler's lock is held): `report` says what each thread waits
    /// on. Expected to end the process; if it returns, the threads simply go on waiting.
    std::function<void(const std::string& report)> deadlock;
    /// Every thread waits, nothing in the process can wake any of them and no real timer is
    /// armed, but another process could (the scheduler's lock is held): `outside_fds` are the
    /// descriptors waited on that only another process can make ready, `other` says a wait
    /// depends on another process some other way (a process-shared object, a child without a
    /// pidfd), `threads` each thread's wait in words. A whole run can then be seen deadlocked
    /// across its processes (linux/process_waits.hpp). Unset: nothing is said.
    std::function<void(const std::vector<int>& outside_fds, bool other, const std::vector<std::string>& threads)> stuck;
    /// A wait ended (or a thread started) after `stuck` was called: the process runs again.
    std::function<void()> unstuck;
  };

  /// How a wait ends.
  enum class End : std::uint8_t {
    timed_out,    ///< virtual time reached the deadline
    ready,        ///< a descriptor became ready, or try_now / ready succeeded
    notified,     ///< notify() or grant() on the wait's object
    interrupted,  ///< a signal handler ran (interruptible waits only)
    aborted,      ///< after_register returned false
  };

  /// One covered wait, described by the caller (the preload's interposers, or a test).
  struct Wait {
    const char* call = nullptr;             ///< the covered call, for the deadlock report ("read")
    Tick deadline = kNever;                 ///< virtual tick at which the wait times out
    /// The caller's timeout lies past the last time the clocks can show (KTIME_MAX): deadline is
    /// kNever, and the report says so instead of "no timeout".
    bool timeout_beyond_end = false;
    /// Another process may end the wait (a process-shared semaphore or condition variable).
    bool outside = false;
    std::span<const pollfd> fds;            ///< real descriptors whose readiness ends the wait
    bool watches_board = false;             ///< fds include lines with edge events: the next edge is a wake-up
    const void* object = nullptr;           ///< notify(object) / grant(object) ends the wait
    const std::atomic<pid_t>* joined_tid = nullptr;  ///< pthread_join: the joined thread's id, once it runs (report)
    /// What the wait is on, in words for the deadlock report ("on the mutex at 0x..., held by
    /// thread 12"), instead of "on the object at 0x..."; called with the scheduler's lock held.
    std::function<std::string()> describe;
    const sigset_t* sigmask = nullptr;      ///< signal mask while blocked (ppoll, pselect, epoll_pwait)
    bool interruptible = true;              ///< a signal handler ends the wait (else it goes on)
    /// Checked under the scheduler's lock before registering: true ends the wait at once (ready).
    std::function<bool()> try_now;
    /// Called outside the lock once the wait is registered (a condition variable releases its
    /// mutex here, so a notify after it cannot be lost). The thread counts as running until it
    /// returns, so time does not move while a thread blocked on that mutex cannot have it yet.
    /// false aborts the wait.
    std::function<bool()> after_register;
    /// In-process readiness besides `fds` (e.g. a semaphore taken for the waiter): checked before
    /// every jump and every `recheck_ns` of real time; true ends the wait (ready).
    std::function<bool()> ready;
    std::int64_t recheck_ns = 0;            ///< real period of the `ready` check (0: only before jumps)
  };

  /// `threads` threads exist already and count as running. `idle_ns` is the grace (0: none).
  VirtualScheduler(Hooks hooks, std::int64_t idle_ns, int threads);
  ~VirtualScheduler();
  VirtualScheduler(const VirtualScheduler&) = delete;
  VirtualScheduler& operator=(const VirtualScheduler&) = delete;

  /// Blocks the calling thread in `w` until it ends; may move time (when this thread was the last
  /// one running). Returns at once (timed_out) when the deadline is not in the future.
  End wait(const Wait& w);
  /// Counts the calling thread as waiting for `w.object` while `block` runs (a real blocking call
  /// that returns by itself, such as pthread_join); notify(object) marks it running again. When
  /// `w.try_now` (checked under the lock) says the object is done already, `block` runs uncounted.
  void wait_in(const Wait& w, const std::function<void()>& block);

  /// Ends the wait of the first waiter on `object` (all of them with `all`), in registration
  /// order, as notified. Returns how many were woken.
  int notify(const void* object, bool all);
  /// Ends the waits of thread `thread` as interrupted (pthread_cancel: the thread then acts on
  /// the cancellation as it leaves). Returns how many were ended.
  int interrupt(pthread_t thread);
  /// Hands one unit of `object` (a semaphore post) to its first waiter. False: nobody waits on
  /// it (or this thread already holds the scheduler's lock: a post from a signal handler), and the
  /// caller posts for real.
  bool grant(const void* object);

  /// A thread is about to be created (it counts as running from now on).
  void thread_started();
  /// The calling thread ends; waiters in wait_in(`joined`) are notified (nullptr: none).
  void thread_exited(const void* joined);
  /// A thread creation failed after thread_started().
  void thread_not_started();

  /// Arms timer `id` to fire at `tick` (kNever: disarms). A fired timer is disarmed.
  void set_timer(int id, Tick tick);

  /// Threads counted as running (for tests and diagnostics).
  int running() const;
  /// Threads in a wait now.
  int waiting() const;
  /// Whether the idle grace has moved time on at least once.
  bool idle_grace_used() const { return idle_logged_.load(std::memory_order_acquire); }

  /// fork() in a threaded program: hold the lock across it (prepare / parent), and in the child,
  /// which has one thread, forget the parent's waiters and give the thread its own wake-up fd.
  /// A snapshot's child (the preload's fork server, forked with the lock held by its one
  /// thread): the calling thread gets a wake-up descriptor of its own, not the parent's.
  void renew_wake_fd();
  void before_fork();
  void after_fork_parent();
  void after_fork_child();

 private:
  struct Waiter;

  End block(Waiter& me);
  void leave_wait(Waiter& me);
  void count_waiting_locked(Waiter& me);
  void decide_locked(bool forced);
  void check_deadlock_locked(bool outside);
  bool waits_outside_locked() const;
  std::string deadlock_report_locked() const;
  std::vector<std::string> thread_lines_locked() const;
  void running_again_locked();
  bool wake_ready_locked();
  void end_locked(Waiter& w, End how);
  void remove_locked(Waiter& w);
  void touch();
  std::int64_t real_now() const;

  Hooks hooks_;
  std::int64_t idle_ns_;
  mutable std::mutex m_;
  int running_;
  std::vector<Waiter*> waiters_;          // registration order
  std::map<int, Tick> timers_;            // armed timers: id -> tick
  std::uint64_t next_seq_ = 0;
  std::atomic<std::int64_t> last_activity_ns_{0};
  std::atomic<bool> idle_logged_{false};
  // A decision stopped after kMaxEmptyJumps jumps that woke nobody: a waiter takes it up again.
  bool redecide_ = false;
  bool outside_logged_ = false;
  bool stuck_said_ = false;  // Hooks::stuck was called and no wait has ended since
};

}  // namespace l6470emu
