// VirtualScheduler with real std::threads and a plain tick counter for the board: the order and
// virtual times of wake-ups are exact however the host schedules the threads; only the idle-grace
// test uses real time (a tiny injected grace).
#include "linux/virtual_scheduler.hpp"

#include <gtest/gtest.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace l6470emu::test {
namespace {

using End = VirtualScheduler::End;

/// A board stand-in: a tick, the jumps made to it, and an optional edge at a fixed tick that
/// makes a pipe readable when time reaches it.
struct FakeBoard {
  std::atomic<Tick> now{0};
  std::vector<Tick> jumps;
  Tick edge = kNever;
  int edge_pipe = -1;
  std::vector<std::pair<int, Tick>> fired;
  std::vector<std::string> log;

  VirtualScheduler::Hooks hooks() {
    VirtualScheduler::Hooks h;
    h.now = [this] { return now.load(); };
    h.advance_to = [this](Tick t) {
      if (t > now) now = t;
      jumps.push_back(t);
      if (edge != kNever && now >= edge) {
        edge = kNever;
        [[maybe_unused]] const ssize_t n = ::write(edge_pipe, "e", 1);
      }
    };
    h.next_edge = [this] { return edge; };
    h.fire_timer = [this](int id) { fired.emplace_back(id, now.load()); };
    h.log = [this](std::string_view s) { log.emplace_back(s); };
    return h;
  }
};

/// What threads saw, in the order they saw it (one mutex: appends from several threads).
struct Journal {
  std::mutex m;
  std::vector<std::string> lines;
  void add(const std::string& s) {
    std::lock_guard lock(m);
    lines.push_back(s);
  }
};

/// A thread known to the scheduler: counted from before its creation, joined through wait_in.
class Worker {
 public:
  template <typename F>
  Worker(VirtualScheduler& s, F body) : s_(s) {
    s_.thread_started();
    t_ = std::thread([this, body] {
      body();
      exited_ = true;
      s_.thread_exited(this);
    });
  }
  void join() {
    VirtualScheduler::Wait w;
    w.object = this;
    w.try_now = [this] { return exited_.load(); };  // as pthread_join's: a thread gone already is no wait
    s_.wait_in(w, [this] { t_.join(); });
  }
  ~Worker() {
    if (t_.joinable()) t_.join();
  }
  pthread_t handle() { return t_.native_handle(); }

 private:
  VirtualScheduler& s_;
  std::atomic<bool> exited_{false};
  std::thread t_;
};

End sleep_until(VirtualScheduler& s, Tick deadline) {
  VirtualScheduler::Wait w;
  w.deadline = deadline;
  return s.wait(w);
}

void wait_until_waiting(VirtualScheduler& s, int n) {
  while (s.waiting() < n) std::this_thread::sleep_for(std::chrono::microseconds(100));
}

TEST(VirtualScheduler, TwoSleepersWakeInDeadlineOrderAtTheirExactVirtualTimes) {
  for (int round = 0; round < 20; ++round) {
    FakeBoard board;
    VirtualScheduler s(board.hooks(), 0, 1);
    Journal j;
    Worker late(s, [&] {
      EXPECT_EQ(sleep_until(s, 3000), End::timed_out);
      j.add("late@" + std::to_string(board.now.load()));
    });
    Worker early(s, [&] {
      EXPECT_EQ(sleep_until(s, 1000), End::timed_out);
      j.add("early@" + std::to_string(board.now.load()));
    });
    late.join();
    early.join();
    EXPECT_EQ(j.lines, (std::vector<std::string>{"early@1000", "late@3000"}));
    EXPECT_EQ(board.jumps, (std::vector<Tick>{1000, 3000}));
    EXPECT_EQ(s.running(), 1);
  }
}

TEST(VirtualScheduler, ASingleThreadSleepingJumpsStraightToItsDeadline) {
  FakeBoard board;
  VirtualScheduler s(board.hooks(), 0, 1);
  EXPECT_EQ(sleep_until(s, 4'000'000), End::timed_out);
  EXPECT_EQ(board.now.load(), 4'000'000u);
  EXPECT_EQ(sleep_until(s, 10), End::timed_out);  // already past: no wait, no jump
  EXPECT_EQ(board.jumps, (std::vector<Tick>{4'000'000}));
}

TEST(VirtualScheduler, JoiningASleeperCountsAsWaitingSoTheSleepEnds) {
  FakeBoard board;
  VirtualScheduler s(board.hooks(), 0, 1);
  Tick woke = 0;
  Worker sleeper(s, [&] {
    sleep_until(s, 5000);
    woke = board.now.load();
  });
  sleeper.join();
  EXPECT_EQ(woke, 5000u);
  EXPECT_EQ(board.now.load(), 5000u);
}

TEST(VirtualScheduler, ANotifiedWaiterRunsOnAtTheNotifiersTimeNotAtItsTimeout) {
  for (int round = 0; round < 20; ++round) {
    FakeBoard board;
    VirtualScheduler s(board.hooks(), 0, 1);
    int cond = 0;  // stands for a condition variable's address
    End end = End::aborted;
    Tick woke = 0;
    Worker waiter(s, [&] {
      VirtualScheduler::Wait w;
      w.deadline = 10'000;
      w.object = &cond;
      end = s.wait(w);
      woke = board.now.load();
    });
    wait_until_waiting(s, 1);
    sleep_until(s, 100);  // the waiter's timeout is later: time jumps to 100 only
    EXPECT_EQ(s.notify(&cond, false), 1);
    waiter.join();
    EXPECT_EQ(end, End::notified);
    EXPECT_EQ(woke, 100u);
    EXPECT_EQ(board.jumps, (std::vector<Tick>{100}));
  }
}

// CPython's GIL, caught at the wrong moment: thread A holds the GIL's mutex between seeing the GIL
// taken and its timed condition wait; the holder, B, dropping the GIL, blocks on that mutex. A's
// wait releases the mutex once registered, and until then A still runs: time must not jump to
// A's timeout meanwhile (it did, and a threaded Python program ran 5 ms late once in many runs).
TEST(VirtualScheduler, AConditionWaitCountsAsRunningUntilItHasReleasedItsMutex) {
  FakeBoard board;
  VirtualScheduler s(board.hooks(), 0, 1);  // the test's thread is B, the GIL's holder
  std::mutex gil_mutex;
  int gil_cond = 0;  // stands for the condition variable's address
  std::atomic<bool> a_holds_mutex{false};
  End a_end = End::aborted;
  Tick a_woke = kNever;
  Worker a(s, [&] {
    gil_mutex.lock();
    a_holds_mutex = true;
    wait_until_waiting(s, 1);  // B waits for the mutex
    VirtualScheduler::Wait w;
    w.deadline = 5'000;
    w.object = &gil_cond;
    w.after_register = [&] {
      gil_mutex.unlock();
      s.notify(&gil_mutex, false);
      return true;
    };
    a_end = s.wait(w);
    a_woke = board.now.load();
  });
  while (!a_holds_mutex) std::this_thread::sleep_for(std::chrono::microseconds(100));
  VirtualScheduler::Wait lock;
  lock.object = &gil_mutex;
  lock.try_now = [&] { return gil_mutex.try_lock(); };
  lock.ready = lock.try_now;
  while (s.wait(lock) != End::ready) {
  }
  EXPECT_EQ(s.notify(&gil_cond, false), 1);  // the GIL dropped: A is woken, not timed out
  gil_mutex.unlock();
  a.join();
  EXPECT_EQ(a_end, End::notified);
  EXPECT_EQ(a_woke, 0u);
  EXPECT_TRUE(board.jumps.empty());
}

TEST(VirtualScheduler, APostIsGrantedToTheFirstWaiterInRegistrationOrder) {
  FakeBoard board;
  VirtualScheduler s(board.hooks(), 0, 1);
  int sem = 0;
  Journal j;
  auto waiter = [&](const std::string& name) {
    return [&, name] {
      VirtualScheduler::Wait w;
      w.object = &sem;
      if (s.wait(w) == End::notified) j.add(name);
    };
  };
  Worker first(s, waiter("first"));
  wait_until_waiting(s, 1);
  Worker second(s, waiter("second"));
  wait_until_waiting(s, 2);
  EXPECT_TRUE(s.grant(&sem));
  first.join();
  EXPECT_TRUE(s.grant(&sem));
  second.join();
  EXPECT_FALSE(s.grant(&sem));  // nobody waits: the caller posts for real
  EXPECT_EQ(j.lines, (std::vector<std::string>{"first", "second"}));
  EXPECT_TRUE(board.jumps.empty());
}

TEST(VirtualScheduler, ADescriptorMadeReadyByAnotherThreadEndsTheWaitBeforeAnyJump) {
  for (int round = 0; round < 20; ++round) {
    FakeBoard board;
    VirtualScheduler s(board.hooks(), 0, 1);
    int p[2];
    ASSERT_EQ(pipe(p), 0);
    End end = End::aborted;
    Tick woke = 0;
    Worker reader(s, [&] {
      const pollfd fd{p[0], POLLIN, 0};
      VirtualScheduler::Wait w;
      w.deadline = 1'000'000;
      w.fds = std::span<const pollfd>(&fd, 1);
      end = s.wait(w);
      woke = board.now.load();
    });
    wait_until_waiting(s, 1);
    ASSERT_EQ(::write(p[1], "x", 1), 1);
    // The reader may not have been scheduled yet; the check before the jump finds it ready.
    sleep_until(s, 10);
    reader.join();
    EXPECT_EQ(end, End::ready);
    EXPECT_EQ(woke, 0u);
    EXPECT_EQ(board.jumps, (std::vector<Tick>{10}));
    ::close(p[0]);
    ::close(p[1]);
  }
}

TEST(VirtualScheduler, AWaiterWatchingTheBoardWakesAtTheEdgeTick) {
  FakeBoard board;
  int p[2];
  ASSERT_EQ(pipe(p), 0);
  board.edge = 250;
  board.edge_pipe = p[1];
  VirtualScheduler s(board.hooks(), 0, 1);
  const pollfd fd{p[0], POLLIN, 0};
  VirtualScheduler::Wait w;
  w.deadline = 4000;
  w.fds = std::span<const pollfd>(&fd, 1);
  w.watches_board = true;
  EXPECT_EQ(s.wait(w), End::ready);
  EXPECT_EQ(board.now.load(), 250u);
  ::close(p[0]);
  ::close(p[1]);
}

TEST(VirtualScheduler, AnArmedTimerFiresAtItsTickOnTheWayToALaterDeadline) {
  FakeBoard board;
  VirtualScheduler s(board.hooks(), 0, 1);
  s.set_timer(7, 400);
  s.set_timer(8, 600);
  s.set_timer(8, kNever);  // disarmed
  EXPECT_EQ(sleep_until(s, 1000), End::timed_out);
  EXPECT_EQ(board.fired, (std::vector<std::pair<int, Tick>>{{7, 400}}));
  EXPECT_EQ(board.jumps, (std::vector<Tick>{400, 1000}));
}

TEST(VirtualScheduler, ATryThatSucceedsEndsTheWaitWithoutRegistering) {
  FakeBoard board;
  VirtualScheduler s(board.hooks(), 0, 1);
  VirtualScheduler::Wait w;
  w.deadline = 100;
  w.try_now = [] { return true; };
  EXPECT_EQ(s.wait(w), End::ready);
  EXPECT_TRUE(board.jumps.empty());
}

TEST(VirtualScheduler, WithAThreadOutsideAnyWaitTimeMovesOnlyAfterTheIdleGraceAndSaysSoOnce) {
  FakeBoard board;
  // Two threads: this one, and one that never waits (blocked in something uncovered).
  VirtualScheduler s(board.hooks(), 20'000'000, 2);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(sleep_until(s, 500), End::timed_out);
  EXPECT_GE(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(20));
  EXPECT_EQ(board.now.load(), 500u);  // still exactly the deadline
  EXPECT_EQ(sleep_until(s, 900), End::timed_out);
  EXPECT_EQ(board.now.load(), 900u);
  ASSERT_EQ(board.log.size(), 1u);
  EXPECT_NE(board.log[0].find("may not repeat exactly"), std::string::npos) << board.log[0];
  EXPECT_TRUE(s.idle_grace_used());
}

void on_signal(int) {}

TEST(VirtualScheduler, ASignalHandlerInterruptsAnInterruptibleWait) {
  struct sigaction sa {};
  sa.sa_handler = on_signal;  // no SA_RESTART: like the kernel, the wait ends with EINTR
  struct sigaction old {};
  ASSERT_EQ(sigaction(SIGUSR1, &sa, &old), 0);
  FakeBoard board;
  VirtualScheduler s(board.hooks(), 0, 2);  // the second thread stands for one that never waits
  std::atomic<bool> done{false};
  End end = End::aborted;
  Worker sleeper(s, [&] {
    end = sleep_until(s, 1'000'000);
    done = true;
  });
  wait_until_waiting(s, 1);
  // A signal sent just before the thread enters ppoll is handled there and lost: send until it ends.
  for (int i = 0; i < 1000 && !done; ++i) {
    pthread_kill(sleeper.handle(), SIGUSR1);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  sleeper.join();
  EXPECT_EQ(end, End::interrupted);
  EXPECT_EQ(board.now.load(), 0u);
  sigaction(SIGUSR1, &old, nullptr);
}

TEST(VirtualScheduler, InterruptingAThreadEndsItsWaitWithoutMovingTime) {
  FakeBoard board;
  VirtualScheduler s(board.hooks(), 0, 1);
  End end = End::aborted;
  Worker waiter(s, [&] {
    VirtualScheduler::Wait w;  // no deadline, nothing to notify it: only interrupt() ends it
    w.interruptible = false;
    end = s.wait(w);
  });
  wait_until_waiting(s, 1);
  EXPECT_EQ(s.interrupt(waiter.handle()), 1);
  waiter.join();
  EXPECT_EQ(end, End::interrupted);
  EXPECT_TRUE(board.jumps.empty());
}

TEST(VirtualScheduler, ManyThreadsSleepingInALoopSeeTheSameTimesEveryRun) {
  std::vector<std::string> first;
  for (int round = 0; round < 5; ++round) {
    FakeBoard board;
    VirtualScheduler s(board.hooks(), 0, 1);
    Journal j;
    std::vector<std::unique_ptr<Worker>> ws;
    for (int k = 1; k <= 4; ++k)
      ws.push_back(std::make_unique<Worker>(s, [&, k] {
        Tick t = 0;
        for (int i = 0; i < 25; ++i) {
          t += static_cast<Tick>(k) * 7;
          sleep_until(s, t);
          std::lock_guard lock(j.m);
          j.lines.push_back(std::to_string(k) + "@" + std::to_string(board.now.load()));
        }
      }));
    for (auto& w : ws) w->join();
    // Lines at one tick come in any order; per thread, the sequence is fixed.
    std::vector<std::string> sorted = j.lines;
    std::sort(sorted.begin(), sorted.end());
    if (round == 0)
      first = sorted;
    else
      EXPECT_EQ(sorted, first);
    for (const std::string& l : j.lines) {
      const int k = std::stoi(l.substr(0, 1));
      EXPECT_EQ(std::stoul(l.substr(2)) % static_cast<unsigned long>(k * 7), 0u) << l;
    }
  }
}

TEST(VirtualScheduler, MoreEdgesThanOneDecisionTakesBeforeADeadlineAreWorkedThroughNotLeftHanging) {
  // An edge at every tick that wakes nobody (a line nobody waits on toggling): one decision stops
  // after 10^5 of them, and the waiter takes the decision up again until its deadline comes.
  FakeBoard board;
  VirtualScheduler::Hooks h = board.hooks();
  h.next_edge = [&board] { return board.now.load() + 1; };
  VirtualScheduler s(std::move(h), 0, 1);
  VirtualScheduler::Wait w;
  w.deadline = 250'000;
  w.watches_board = true;
  EXPECT_EQ(s.wait(w), End::timed_out);
  EXPECT_EQ(board.now.load(), 250'000u);
}

/// A pipe whose read end the waiters of the deadlock tests poll: writing to it ends their waits.
struct WakePipe {
  int fd[2] = {-1, -1};
  WakePipe() { EXPECT_EQ(pipe(fd), 0); }
  ~WakePipe() {
    close(fd[0]);
    close(fd[1]);
  }
  void wake() const { [[maybe_unused]] const ssize_t n = ::write(fd[1], "w", 1); }
};

/// Two threads (the test's own and a worker) wait on `pipe` with no deadline, `hooks` as given.
/// Returns the deadlock reports the hook got.
std::vector<std::string> both_wait_on(FakeBoard& board, VirtualScheduler::Hooks hooks, const WakePipe& pipe,
                                      bool outside = false) {
  std::vector<std::string> reports;
  std::atomic<bool> reported{false};
  hooks.deadlock = [&](const std::string& report) {
    reports.push_back(report);
    reported = true;
    pipe.wake();  // the hook must end the process; this one ends the waits instead
  };
  VirtualScheduler s(std::move(hooks), 0, 1);
  // A thread the scheduler does not count (another process, as far as it knows) wakes them
  // when no deadlock ends the waits (once both wait: up to 10 s for a loaded machine to get there).
  std::thread outsider([&] {
    for (int i = 0; i < 10000 && s.waiting() < 2 && !reported; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    pipe.wake();
  });
  const pollfd p{pipe.fd[0], POLLIN, 0};
  auto wait_on_pipe = [&](const char* call) {
    VirtualScheduler::Wait w;
    w.call = call;
    w.fds = std::span<const pollfd>(&p, 1);
    w.outside = outside;
    return s.wait(w);
  };
  Worker worker(s, [&] { EXPECT_EQ(wait_on_pipe("read"), End::ready); });
  wait_until_waiting(s, 1);
  EXPECT_EQ(wait_on_pipe("poll"), End::ready);
  worker.join();
  outsider.join();
  EXPECT_TRUE(board.jumps.empty());
  return reports;
}

TEST(VirtualSchedulerDeadlock, EveryThreadWaitingOnWhatOnlyTheProcessCouldEndIsReportedWithWhatEachWaitsOn) {
  FakeBoard board;
  WakePipe pipe;
  VirtualScheduler::Hooks h = board.hooks();
  h.inside_fd = [&](int fd) { return fd == pipe.fd[0]; };
  h.describe_fd = [](int fd) { return "fd " + std::to_string(fd) + " (a line request)"; };
  h.describe_board = [] { return std::string("chip 0 BUSY high\nno edge to come"); };
  const std::vector<std::string> reports = both_wait_on(board, h, pipe);
  ASSERT_EQ(reports.size(), 1u);
  const std::string& r = reports[0];
  EXPECT_EQ(r.rfind("virtual time: deadlock at t=0.000000 s: every thread waits and nothing can wake any of them", 0), 0u)
      << r;
  EXPECT_NE(r.find("the run ends with exit status 87"), std::string::npos) << r;
  const std::string fd = "fd " + std::to_string(pipe.fd[0]) + " (a line request), no timeout";
  EXPECT_NE(r.find("): read() on " + fd), std::string::npos) << r;
  EXPECT_NE(r.find("): poll() on " + fd), std::string::npos) << r;
  EXPECT_NE(r.find("\n  chip 0 BUSY high\n  no edge to come"), std::string::npos) << r;
}

TEST(VirtualSchedulerDeadlock, IsNotDeclaredWhileAWaitCouldBeEndedFromOutsideTheProcess) {
  WakePipe pipe;
  {
    FakeBoard board;  // a descriptor another process may write to
    VirtualScheduler::Hooks h = board.hooks();
    h.inside_fd = [](int) { return false; };
    EXPECT_TRUE(both_wait_on(board, h, pipe).empty());
  }
  char drain[8];
  [[maybe_unused]] ssize_t n = ::read(pipe.fd[0], drain, sizeof drain);
  {
    FakeBoard board;  // a process-shared semaphore or condition variable
    VirtualScheduler::Hooks h = board.hooks();
    h.inside_fd = [](int) { return true; };
    EXPECT_TRUE(both_wait_on(board, h, pipe, true).empty());
  }
  n = ::read(pipe.fd[0], drain, sizeof drain);
  {
    FakeBoard board;  // an armed alarm: its signal may come (said once)
    VirtualScheduler::Hooks h = board.hooks();
    h.inside_fd = [](int) { return true; };
    h.outside_wakeup = [] { return std::string("an alarm() is armed"); };
    EXPECT_TRUE(both_wait_on(board, h, pipe).empty());
    ASSERT_EQ(board.log.size(), 1u);
    EXPECT_NE(board.log[0].find("but an alarm() is armed: waiting for its signal in real time"), std::string::npos);
  }
}

TEST(VirtualSchedulerDeadlock, IsNotDeclaredWhileAThreadRunsOrAWakeUpIsToCome) {
  FakeBoard board;
  std::vector<std::string> reports;
  VirtualScheduler::Hooks h = board.hooks();
  h.inside_fd = [](int) { return true; };
  h.deadlock = [&](const std::string& r) { reports.push_back(r); };
  VirtualScheduler s(std::move(h), 0, 1);
  int object = 0;
  Worker waiter(s, [&] {
    VirtualScheduler::Wait w;  // no deadline: only notify() ends it
    w.object = &object;
    EXPECT_EQ(s.wait(w), End::notified);
  });
  wait_until_waiting(s, 1);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));  // this thread runs: no verdict
  EXPECT_EQ(sleep_until(s, 500), End::timed_out);  // a deadline to come: time jumps instead
  EXPECT_EQ(s.notify(&object, false), 1);
  waiter.join();
  EXPECT_TRUE(reports.empty());
  EXPECT_EQ(board.jumps, (std::vector<Tick>{500}));
}

TEST(VirtualSchedulerDeadlock, IsNotDeclaredWhenAPipesLastOtherHolderClosesItWhileItIsLookedAt) {
  // The slow look at who holds the pipe (here: the hook) races the writer's last close: the end
  // of file it leaves ends the read's wait instead of making it a deadlock.
  FakeBoard board;
  int fd[2];
  ASSERT_EQ(pipe(fd), 0);
  std::vector<std::string> reports;
  VirtualScheduler::Hooks h = board.hooks();
  h.inside_fd = [&](int) {
    if (fd[1] >= 0) close(std::exchange(fd[1], -1));  // the writer ends meanwhile
    return true;                                        // and nobody else holds it now
  };
  h.deadlock = [&](const std::string& r) { reports.push_back(r); };
  VirtualScheduler s(std::move(h), 0, 1);
  const pollfd p{fd[0], POLLIN, 0};
  VirtualScheduler::Wait w;
  w.call = "read";
  w.fds = std::span<const pollfd>(&p, 1);
  EXPECT_EQ(s.wait(w), End::ready);
  EXPECT_TRUE(reports.empty());
  close(fd[0]);
}

TEST(VirtualSchedulerDeadlock, AWaitOnlyAnotherProcessCanEndIsSaidOnceWithWhatItWaitsOnAndUnsaidWhenItEnds) {
  FakeBoard board;
  WakePipe pipe;
  std::vector<std::vector<int>> said;
  std::vector<std::string> lines;
  int unsaid = 0;
  VirtualScheduler::Hooks h = board.hooks();
  h.inside_fd = [](int) { return false; };
  h.time_limit = [] { return Tick{4'000'000}; };  // a run's limit: not jumped to while another process may act
  h.stuck = [&](const std::vector<int>& fds, bool other, const std::vector<std::string>& threads) {
    said.push_back(fds);
    EXPECT_FALSE(other);
    lines = threads;
  };
  h.unstuck = [&] { ++unsaid; };
  const std::vector<std::string> reports = both_wait_on(board, h, pipe);
  EXPECT_TRUE(reports.empty());
  ASSERT_FALSE(said.empty());
  EXPECT_EQ(said.back(), (std::vector<int>{pipe.fd[0], pipe.fd[0]}));  // both threads' waits
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NE(lines[0].find(": read() on fd "), std::string::npos) << lines[0];
  EXPECT_NE(lines[1].find(": poll() on fd "), std::string::npos) << lines[1];
  EXPECT_EQ(unsaid, static_cast<int>(said.size()));  // withdrawn as soon as a wait ended
}

}  // namespace
}  // namespace l6470emu::test
