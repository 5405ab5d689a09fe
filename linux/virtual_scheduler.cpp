// Virtual host time's scheduler: thread accounting, waits blocked on a per-thread eventfd, and
// the jump of virtual time when every thread waits. No libc function is replaced here.
#include "linux/virtual_scheduler.hpp"

#include <errno.h>
#include <fcntl.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <string>

#include "linux/clock.hpp"

namespace l6470emu {
namespace {

// At most this many jumps that wake nobody (edges or timers no waiter sees) in one decision.
constexpr int kMaxEmptyJumps = 100'000;
// A thread whose wake-up eventfd could not be made looks at its state this often instead.
constexpr std::int64_t kFallbackPollNs = 1'000'000;

// Whether this thread holds the scheduler's lock (a semaphore post from a signal handler
// interrupting the scheduler must not take it again).
thread_local bool t_holds_lock = false;

// The calling thread's wake-up descriptor: the scheduler writes it to end the thread's wait.
// It also keeps the thread's id, asked for once: a gettid() system call in every wait was half
// the cost of a virtual-time spidev round trip.
struct ThreadWakeFd {
  int fd = -1;
  pid_t tid = 0;
  ~ThreadWakeFd() {
    if (fd >= 0) ::close(fd);
    fd = -1;  // a wait after this (another key's destructor) makes a new one, never reuses the number
  }
  int get() {
    if (fd < 0) fd = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    return fd;
  }
  void renew() {
    if (fd >= 0) ::close(fd);
    fd = -1;
    tid = 0;  // (after fork: the child's thread has an id of its own)
    get();
  }
  pid_t thread_id() {
    if (tid == 0) tid = ::gettid();
    return tid;
  }
  void drain() const {
    std::uint64_t v;
    if (fd >= 0) [[maybe_unused]] const ssize_t n = ::read(fd, &v, sizeof v);
  }
};
thread_local ThreadWakeFd t_wake;

class Locked {
 public:
  explicit Locked(std::mutex& m) : lock_(m) { t_holds_lock = true; }
  ~Locked() { t_holds_lock = false; }

 private:
  std::unique_lock<std::mutex> lock_;
};

// Runs `f` when the scope ends, also when a cancelled thread unwinds through it.
template <typename F>
class OnExit {
 public:
  explicit OnExit(F f) : f_(std::move(f)) {}
  ~OnExit() { f_(); }
  OnExit(const OnExit&) = delete;
  OnExit& operator=(const OnExit&) = delete;

 private:
  F f_;
};

timespec to_timespec(std::int64_t ns) {
  return {static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
}

// A thread's name as the kernel has it (/proc/self/task/TID/comm), or "".
std::string thread_name(pid_t tid) {
  const std::string path = "/proc/self/task/" + std::to_string(tid) + "/comm";
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return {};
  char buf[64];
  const ssize_t n = ::read(fd, buf, sizeof buf - 1);
  ::close(fd);
  if (n <= 0) return {};
  std::string name(buf, static_cast<std::size_t>(n));
  while (!name.empty() && (name.back() == '\n' || name.back() == '\0')) name.pop_back();
  for (char& c : name)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7F) c = '?';
  return name;
}

std::string seconds_of(Tick t) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%" PRIu64 ".%06" PRIu64, static_cast<std::uint64_t>(t / kTicksPerSecond),
                static_cast<std::uint64_t>(t % kTicksPerSecond / 4));
  return buf;
}

}  // namespace

struct VirtualScheduler::Waiter {
  const Wait* w = nullptr;
  pthread_t owner = pthread_self();
  pid_t tid = t_wake.thread_id();
  int fd = -1;  // the waiting thread's wake-up eventfd
  std::uint64_t seq = 0;
  std::atomic<bool> done{false};
  End end = End::timed_out;
  bool deciding = false;  // its own thread is deciding: no need to wake it through the eventfd
  bool woken = false;     // the eventfd was written for it
  bool counted = false;   // counted as waiting (running_ lowered for it)
};

VirtualScheduler::VirtualScheduler(Hooks hooks, std::int64_t idle_ns, int threads)
    : hooks_(std::move(hooks)), idle_ns_(idle_ns > 0 ? idle_ns : 0), running_(threads) {
  touch();
}

VirtualScheduler::~VirtualScheduler() = default;

std::int64_t VirtualScheduler::real_now() const { return hooks_.real_ns ? hooks_.real_ns() : monotonic_ns(); }

void VirtualScheduler::touch() { last_activity_ns_.store(real_now(), std::memory_order_release); }

VirtualScheduler::End VirtualScheduler::wait(const Wait& w) {
  Waiter me;
  me.w = &w;
  me.fd = t_wake.get();
  {
    Locked lock(m_);
    if (w.try_now && w.try_now()) return End::ready;
    if (w.deadline <= hooks_.now()) return End::timed_out;
    me.seq = next_seq_++;
    waiters_.push_back(&me);
    // With after_register (a condition variable releasing its mutex) the thread is registered,
    // so a notify cannot be lost, but counts as running until that has run: a thread blocked on
    // the mutex can take it only then, and time must not jump to this wait's timeout before.
    if (!w.after_register) count_waiting_locked(me);
  }
  const OnExit leave([&] { leave_wait(me); });
  if (w.after_register) {
    const bool registered = w.after_register();
    Locked lock(m_);
    if (!me.done.load(std::memory_order_acquire)) {
      if (registered)
        count_waiting_locked(me);
      else
        end_locked(me, End::aborted);
    }
  }
  return block(me);
}

void VirtualScheduler::count_waiting_locked(Waiter& me) {
  me.counted = true;
  --running_;
  touch();
  me.deciding = true;
  decide_locked(false);
  me.deciding = false;
}

void VirtualScheduler::leave_wait(Waiter& me) {
  {
    Locked lock(m_);
    if (!me.done.load(std::memory_order_acquire)) {  // a thread cancelled in its wait, or wait_in
      me.done.store(true, std::memory_order_release);
      if (me.counted) ++running_;
    }
    remove_locked(me);
    touch();
  }
  if (me.woken) t_wake.drain();
}

VirtualScheduler::End VirtualScheduler::block(Waiter& me) {
  const Wait& w = *me.w;
  std::vector<pollfd> pf;
  pf.reserve(w.fds.size() + 1);
  for (const pollfd& p : w.fds) pf.push_back({p.fd, p.events, 0});
  pf.push_back({me.fd, POLLIN, 0});
  const std::size_t own = pf.size() - 1;
  while (!me.done.load(std::memory_order_acquire)) {
    std::int64_t timeout_ns = -1;
    auto at_most = [&](std::int64_t ns) { timeout_ns = timeout_ns < 0 ? ns : std::min(timeout_ns, ns); };
    if (idle_ns_ > 0)
      at_most(std::max<std::int64_t>(kFallbackPollNs,
                                     last_activity_ns_.load(std::memory_order_acquire) + idle_ns_ - real_now()));
    if (w.ready && w.recheck_ns > 0) at_most(w.recheck_ns);
    if (me.fd < 0 || redecide_) at_most(kFallbackPollNs);
    const timespec ts = to_timespec(timeout_ns < 0 ? 0 : timeout_ns);
    for (pollfd& p : pf) p.revents = 0;
    const int n = ::ppoll(pf.data(), pf.size(), timeout_ns < 0 ? nullptr : &ts, w.sigmask);
    const int err = errno;
    Locked lock(m_);
    if (me.done.load(std::memory_order_acquire)) break;
    if (n < 0) {
      if (err == EINTR && w.interruptible) end_locked(me, End::interrupted);
      continue;
    }
    if (n > 0) {
      if (pf[own].revents & POLLNVAL) {  // the program closed our descriptor: make another
        t_wake.fd = -1;
        me.fd = pf[own].fd = t_wake.get();
      } else if (pf[own].revents & POLLIN) {
        t_wake.drain();
      }
      for (std::size_t i = 0; i < own; ++i)
        if (pf[i].revents) {
          end_locked(me, End::ready);
          break;
        }
      continue;
    }
    // A real timeout: the periodic check, a decision to take up again, and the idle grace.
    if (w.ready && w.ready()) {
      end_locked(me, End::ready);
      continue;
    }
    if (redecide_ && running_ == 0) {
      decide_locked(false);
      continue;
    }
    if (idle_ns_ > 0 && running_ > 0 &&
        real_now() - last_activity_ns_.load(std::memory_order_acquire) >= idle_ns_) {
      if (!idle_logged_.exchange(true) && hooks_.log)
        hooks_.log("virtual time: no covered wait was entered or left for " + std::to_string(idle_ns_ / 1'000'000) +
                   " ms while " + std::to_string(running_) +
                   " thread(s) ran outside one (blocked in a call the preload does not cover, or computing); "
                   "time moved on to the next wake-up anyway, so this run may not repeat exactly (idle= sets the grace)");
      touch();
      decide_locked(true);
    }
  }
  return me.end;
}

void VirtualScheduler::wait_in(const Wait& w, const std::function<void()>& block_fn) {
  Waiter me;
  me.w = &w;
  me.fd = t_wake.get();
  bool counted = false;
  {
    Locked lock(m_);
    if (!w.try_now || !w.try_now()) {  // else nothing to wait for: the call runs uncounted
      counted = true;
      me.seq = next_seq_++;
      waiters_.push_back(&me);
      me.counted = true;
      --running_;
      touch();
      decide_locked(false);
    }
  }
  const OnExit leave([&] {
    if (counted) leave_wait(me);
  });
  block_fn();
}

void VirtualScheduler::end_locked(Waiter& w, End how) {
  running_again_locked();
  w.end = how;
  w.done.store(true, std::memory_order_release);
  if (w.counted) ++running_;
  if (w.fd >= 0 && !w.deciding) {
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = ::write(w.fd, &one, sizeof one);
    w.woken = true;
  }
}

void VirtualScheduler::remove_locked(Waiter& w) {
  const auto it = std::find(waiters_.begin(), waiters_.end(), &w);
  if (it != waiters_.end()) waiters_.erase(it);
}

bool VirtualScheduler::wake_ready_locked() {
  bool woke = false;
  std::vector<pollfd> pf;
  for (Waiter* w : waiters_) {
    if (w->done.load(std::memory_order_relaxed)) continue;
    if (!w->w->fds.empty()) {
      // A copy: the waiting thread may be inside ppoll on its own array right now.
      pf.clear();
      for (const pollfd& p : w->w->fds) pf.push_back({p.fd, p.events, 0});
      if (::poll(pf.data(), pf.size(), 0) > 0) {
        end_locked(*w, End::ready);
        woke = true;
        continue;
      }
    }
    if (w->w->ready && w->w->ready()) {
      end_locked(*w, End::ready);
      woke = true;
    }
  }
  return woke;
}

void VirtualScheduler::decide_locked(bool forced) {
  redecide_ = false;
  for (int empty = 0; empty < kMaxEmptyJumps; ++empty) {
    if (waiters_.empty()) return;
    if (running_ > 0 && !forced) return;
    // An in-process hand-off (a descriptor another thread made ready, a semaphore) goes first:
    // that thread runs on at the current time.
    if (wake_ready_locked()) return;
    Tick d = kNever;
    bool board = false;
    for (Waiter* w : waiters_) {
      if (w->done.load(std::memory_order_relaxed)) continue;
      d = std::min(d, w->w->deadline);
      board = board || w->w->watches_board;
    }
    if (board && hooks_.next_edge) d = std::min(d, hooks_.next_edge());
    if (hooks_.next_world) d = std::min(d, hooks_.next_world());
    const Tick limit = hooks_.time_limit ? hooks_.time_limit() : kNever;
    for (const auto& [id, tick] : timers_) d = std::min(d, tick);
    if (d == kNever) {
      // Every thread waits for something outside the process, or for nothing that can come
      // (the time limit aside: it ends a run that goes on, not one that cannot).
      const bool outside = waits_outside_locked();
      // Looked at again after that (slow) look at who holds what: a pipe's last other holder may
      // have closed it meanwhile, which ends its reader's wait rather than making it a deadlock.
      if (wake_ready_locked()) return;
      if (!forced && running_ == 0) check_deadlock_locked(outside);
      // Another process (a child, a pipe's writer) or an armed real timer goes on in real time
      // meanwhile: the program's time does not run on to the limit without it.
      if (limit == kNever || outside || (hooks_.outside_wakeup && !hooks_.outside_wakeup().empty())) return;
    }
    d = std::min(d, limit);
    d = std::max(d, hooks_.now());
    hooks_.advance_to(d);
    for (auto it = timers_.begin(); it != timers_.end();) {
      if (it->second > d) {
        ++it;
        continue;
      }
      const int id = it->first;
      it = timers_.erase(it);
      if (hooks_.fire_timer) hooks_.fire_timer(id);
    }
    bool woke = false;
    for (Waiter* w : waiters_)
      if (!w->done.load(std::memory_order_relaxed) && w->w->deadline <= d) {
        end_locked(*w, End::timed_out);
        woke = true;
      }
    if (wake_ready_locked()) woke = true;
    if (woke) return;
  }
  redecide_ = true;  // so many jumps woke nobody: the waiters take the decision up again shortly
}

void VirtualScheduler::running_again_locked() {
  if (!stuck_said_) return;
  stuck_said_ = false;
  if (hooks_.unstuck) hooks_.unstuck();
}

bool VirtualScheduler::waits_outside_locked() const {
  for (const Waiter* w : waiters_) {
    if (w->done.load(std::memory_order_relaxed)) continue;
    if (w->w->outside) return true;  // another process may post or signal
    for (const pollfd& p : w->w->fds)
      if (!hooks_.inside_fd || !hooks_.inside_fd(p.fd)) return true;  // another process may write to it
  }
  return false;
}

void VirtualScheduler::check_deadlock_locked(bool outside) {
  if (!hooks_.deadlock || running_ > 0) return;
  const bool any = std::any_of(waiters_.begin(), waiters_.end(),
                               [](const Waiter* w) { return !w->done.load(std::memory_order_relaxed); });
  if (!any) return;
  if (outside && !hooks_.stuck) return;
  if (hooks_.outside_wakeup) {
    const std::string why = hooks_.outside_wakeup();
    if (!why.empty()) {
      if (!outside && !outside_logged_ && hooks_.log) {
        outside_logged_ = true;
        hooks_.log("virtual time: every thread waits and nothing in the process can wake them, but " + why +
                   ": waiting for its signal in real time");
      }
      return;
    }
  }
  if (!outside) return hooks_.deadlock(deadlock_report_locked());
  // Only another process can end a wait: say so, for a run to see whether every process waits
  // on another (a deadlock across them).
  std::vector<int> fds;
  bool other = false;
  for (const Waiter* w : waiters_) {
    if (w->done.load(std::memory_order_relaxed)) continue;
    other = other || w->w->outside;
    for (const pollfd& p : w->w->fds)
      if (!hooks_.inside_fd || !hooks_.inside_fd(p.fd)) fds.push_back(p.fd);
  }
  stuck_said_ = true;
  hooks_.stuck(fds, other, thread_lines_locked());
}

std::string VirtualScheduler::deadlock_report_locked() const {
  const Tick now = hooks_.now();
  std::string r = "virtual time: deadlock at t=" + seconds_of(now) +
                  " s: every thread waits and nothing can wake any of them (no timeout, timer or line edge to come); "
                  "the run ends with exit status " + std::to_string(kDeadlockExitStatus);
  for (const std::string& line : thread_lines_locked()) r += "\n  " + line;
  if (hooks_.describe_board) {
    const std::string board = hooks_.describe_board();
    std::size_t at = 0;
    while (at < board.size()) {
      const std::size_t nl = board.find('\n', at);
      const std::size_t end = nl == std::string::npos ? board.size() : nl;
      if (end > at) r += "\n  " + board.substr(at, end - at);
      at = end + 1;
    }
  }
  return r;
}

std::vector<std::string> VirtualScheduler::thread_lines_locked() const {
  std::vector<std::string> lines;
  for (const Waiter* w : waiters_) {
    if (w->done.load(std::memory_order_relaxed)) continue;
    const Wait& wait = *w->w;
    const std::string name = thread_name(w->tid);
    std::string r = "thread " + std::to_string(w->tid) + (name.empty() ? "" : " (" + name + ")") + ": " +
         (wait.call == nullptr ? std::string("a covered wait")
          : std::string_view(wait.call).find(' ') != std::string_view::npos ? std::string(wait.call)
                                                                           : std::string(wait.call) + "()");
    for (std::size_t i = 0; i < wait.fds.size(); ++i)
      r += (i == 0 ? " on " : ", ") + (hooks_.describe_fd ? hooks_.describe_fd(wait.fds[i].fd)
                                                           : "fd " + std::to_string(wait.fds[i].fd));
    if (const pid_t joined = wait.joined_tid ? wait.joined_tid->load(std::memory_order_acquire) : 0; joined != 0) {
      const std::string name_of_joined = thread_name(joined);
      r += " of thread " + std::to_string(joined) + (name_of_joined.empty() ? "" : " (" + name_of_joined + ")");
    } else if (wait.describe) {
      r += " " + wait.describe();
    } else if (wait.fds.empty() && wait.object != nullptr) {
      char obj[32];
      std::snprintf(obj, sizeof obj, "%p", wait.object);
      r += std::string(" on the object at ") + obj;
    }
    if (wait.deadline != kNever)
      r += ", until t=" + seconds_of(wait.deadline) + " s";  // (not reached: a jump would have come first)
    else
      r += wait.timeout_beyond_end ? ", its timeout past the last time the clocks can show (it never ends)"
                                   : ", no timeout";
    lines.push_back(std::move(r));
  }
  return lines;
}

int VirtualScheduler::notify(const void* object, bool all) {
  if (t_holds_lock) return 0;
  Locked lock(m_);
  int n = 0;
  for (Waiter* w : waiters_) {
    if (w->done.load(std::memory_order_relaxed) || w->w->object != object) continue;
    end_locked(*w, End::notified);
    ++n;
    if (!all) break;
  }
  return n;
}

int VirtualScheduler::interrupt(pthread_t thread) {
  if (t_holds_lock) return 0;
  Locked lock(m_);
  int n = 0;
  for (Waiter* w : waiters_)
    if (!w->done.load(std::memory_order_relaxed) && pthread_equal(w->owner, thread)) {
      end_locked(*w, End::interrupted);
      ++n;
    }
  return n;
}

bool VirtualScheduler::grant(const void* object) { return notify(object, false) > 0; }

void VirtualScheduler::thread_started() {
  Locked lock(m_);
  running_again_locked();
  ++running_;
  touch();
}

void VirtualScheduler::thread_not_started() {
  Locked lock(m_);
  --running_;
  touch();
  decide_locked(false);
}

void VirtualScheduler::thread_exited(const void* joined) {
  Locked lock(m_);
  --running_;
  touch();
  if (joined)
    for (Waiter* w : waiters_)
      if (!w->done.load(std::memory_order_relaxed) && w->w->object == joined) end_locked(*w, End::notified);
  decide_locked(false);
}

void VirtualScheduler::set_timer(int id, Tick tick) {
  Locked lock(m_);
  if (tick == kNever)
    timers_.erase(id);
  else
    timers_[id] = tick;
}

int VirtualScheduler::running() const {
  Locked lock(m_);
  return running_;
}

int VirtualScheduler::waiting() const {
  Locked lock(m_);
  return static_cast<int>(std::count_if(waiters_.begin(), waiters_.end(),
                                        [](Waiter* w) { return !w->done.load(std::memory_order_relaxed); }));
}

void VirtualScheduler::renew_wake_fd() {
  t_wake.renew();
  for (Waiter* w : waiters_) w->fd = t_wake.get();  // (one thread: every waiter is this thread's)
}

void VirtualScheduler::before_fork() {
  m_.lock();
  t_holds_lock = true;
}

void VirtualScheduler::after_fork_parent() {
  t_holds_lock = false;
  m_.unlock();
}

void VirtualScheduler::after_fork_child() {
  // The other threads (and their waits) did not survive the fork; the eventfd is shared with
  // the parent's thread, so this thread gets its own.
  waiters_.clear();
  running_ = 1;
  stuck_said_ = false;  // (the parent's word, not this process's)
  t_wake.renew();
  t_holds_lock = false;
  m_.unlock();
  touch();
}

}  // namespace l6470emu
