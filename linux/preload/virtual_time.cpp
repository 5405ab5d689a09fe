// Virtual host time in the preload library: clock conversions, covered waits, the busy-wait
// rule, the board's bus-time waiter, fork hooks.
#include "linux/preload/fd_holders.hpp"
#include "linux/preload/fork_server.hpp"
#include "linux/preload/progress.hpp"
#include "linux/preload/virtual_time.hpp"
#include "linux/preload/coverage.hpp"
#include "linux/preload/run.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <pthread.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "linux/log.hpp"
#include "linux/preload/real.hpp"
#include "linux/process_waits.hpp"
#include "linux/unix_socket_diag.hpp"

namespace l6470emu::preload {

namespace detail {
std::atomic<VirtualHostTime*> g_virtual_time{nullptr};
}

namespace {

std::int64_t real_clock_ns(clockid_t clock) {
  timespec ts{};
  real::clock_gettime(clock, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

// Threads of the process now (the ones that exist before the library is set up count as running).
int count_threads() {
  DIR* d = real::opendir("/proc/self/task");
  if (!d) return 1;
  int n = 0;
  while (const dirent* e = real::readdir(d))
    if (e->d_name[0] != '.') ++n;
  real::closedir(d);
  return std::max(n, 1);
}

// The busy-wait rule's count of looks at time since the calling thread's last covered wait.
thread_local std::int64_t t_looks = 0;

// Why a signal may still come from outside the covered calls: a real timer that is armed.
std::string armed_real_timers() {
  for (const auto& [which, name] : {std::pair{ITIMER_REAL, "an alarm() or setitimer(ITIMER_REAL) timer is armed"},
                                    std::pair{ITIMER_VIRTUAL, "a setitimer(ITIMER_VIRTUAL) timer is armed"},
                                    std::pair{ITIMER_PROF, "a setitimer(ITIMER_PROF) timer is armed"}}) {
    itimerval v{};
    if (getitimer(which, &v) == 0 && (v.it_value.tv_sec != 0 || v.it_value.tv_usec != 0)) return name;
  }
  // POSIX timers (timer_create): listed in /proc/self/timers (when the kernel has it).
  const int fd = real::open("/proc/self/timers", O_RDONLY | O_CLOEXEC, 0);
  if (fd >= 0) {
    char c;
    const ssize_t n = real::read(fd, &c, 1);
    real::close(fd);
    if (n == 1) return "a POSIX timer (timer_create) exists";
  }
  return {};
}

// Whether `fd` is an epoll set; `members` gets the descriptors in it (/proc/self/fdinfo lines
// "tfd:        7 events:       19 data: ...").
bool epoll_members(int fd, std::vector<int>& members) {
  members.clear();
  char link[64] = {};
  const std::string self = "/proc/self/fd/" + std::to_string(fd);
  if (real::readlink(self.c_str(), link, sizeof link - 1) <= 0 || std::strcmp(link, "anon_inode:[eventpoll]") != 0)
    return false;
  const std::string info_path = "/proc/self/fdinfo/" + std::to_string(fd);
  const int info = real::open(info_path.c_str(), O_RDONLY | O_CLOEXEC, 0);
  if (info < 0) return false;
  std::string text;
  char buf[4096];
  for (ssize_t n; (n = real::read(info, buf, sizeof buf)) > 0 && text.size() < (1u << 20);)
    text.append(buf, static_cast<std::size_t>(n));
  real::close(info);
  for (std::size_t at = text.find("tfd:"); at != std::string::npos; at = text.find("tfd:", at + 4))
    members.push_back(std::atoi(text.c_str() + at + 4));
  return true;
}

// Whether descriptor `fd` becomes ready only through this process: an emulated gpio line, a
// virtual timerfd, or an epoll set of such descriptors.
bool inside_fd(int fd, int depth = 0) {
  if (is_emulated_line(fd) || is_virtual_timerfd(fd) || pipe_held_by_this_process_alone(fd) ||
      socket_pair_held_by_this_process_alone(fd))
    return true;
  std::vector<int> members;
  if (depth > 3 || !epoll_members(fd, members)) return false;
  for (const int m : members)
    if (!inside_fd(m, depth + 1)) return false;
  return true;
}

// The child a pidfd refers to (/proc/self/fdinfo's "Pid:" line), or 0 when `fd` is no pidfd.
pid_t pidfd_child(int fd) {
  if (link_of("/proc/self/fd/" + std::to_string(fd)) != "anon_inode:[pidfd]") return 0;
  const std::string path = "/proc/self/fdinfo/" + std::to_string(fd);
  const int info = real::open(path.c_str(), O_RDONLY | O_CLOEXEC, 0);
  if (info < 0) return 0;
  char buf[1024];
  const ssize_t n = real::read(info, buf, sizeof buf - 1);
  real::close(info);
  if (n <= 0) return 0;
  buf[n] = 0;
  const char* at = std::strstr(buf, "Pid:");
  return at ? static_cast<pid_t>(std::atol(at + 4)) : 0;
}

// What another process could do to end a wait on `fd` (linux/process_waits.hpp).
WaitDependency dependency_of(int fd) {
  WaitDependency d;
  const std::string link = link_of("/proc/self/fd/" + std::to_string(fd));
  if (link.rfind("pipe:[", 0) == 0) {
    d.kind = WaitDependency::Kind::pipe;
    d.inode = std::strtoul(link.c_str() + 6, nullptr, 10);
    d.fd = fd;
  } else if (link.rfind("socket:[", 0) == 0) {
    const unsigned long inode = std::strtoul(link.c_str() + 8, nullptr, 10);
    if (const UnixSocketInfo info = unix_socket_info(inode); info.known && info.peer != 0) {
      d.kind = WaitDependency::Kind::socket;
      d.inode = inode;
      d.peer = info.peer;
      d.fd = fd;
    }
  } else if (const pid_t child = pidfd_child(fd); child > 0) {
    d.kind = WaitDependency::Kind::child;
    d.pid = child;
  }
  return d;
}

// Writes every line of `text` on standard error as the log writes them ("l6470emu: ...").
void write_stderr_lines(const std::string& text) {
  std::string out;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t nl = std::min(text.find('\n', at), text.size());
    out += "l6470emu: " + text.substr(at, nl - at) + "\n";
    at = nl + 1;
  }
  raw_write_all(2, out.data(), out.size());
}

}  // namespace

bool kernel_valid(const timespec& ts) { return ts.tv_sec >= 0 && ts.tv_nsec >= 0 && ts.tv_nsec < 1'000'000'000; }

std::int64_t saturated_ns(const timespec& ts) {
  if (ts.tv_sec >= kKtimeMax / 1'000'000'000) return kKtimeMax;  // KTIME_SEC_MAX and beyond
  return add_saturated(std::int64_t{ts.tv_sec} * 1'000'000'000, ts.tv_nsec);
}

std::int64_t add_saturated(std::int64_t a, std::int64_t b) { return a > kKtimeMax - b ? kKtimeMax : a + b; }

VirtualHostTime::VirtualHostTime(DeviceBoard& board, const TimeConfig& config)
    : board_(board),
      time_(board.time()),
      boottime_offset_ns_(real_clock_ns(CLOCK_BOOTTIME) - real_clock_ns(CLOCK_MONOTONIC)),
      tai_offset_ns_(real_clock_ns(CLOCK_TAI) - real_clock_ns(CLOCK_REALTIME)),
      last_tick_([this] {
        // Every clock at most KTIME_MAX: the one with the largest offset from MONOTONIC decides.
        const std::int64_t realtime = time_.realtime_offset_ns();
        const std::int64_t largest = std::max({std::int64_t{0}, boottime_offset_ns_, realtime, realtime + tai_offset_ns_});
        return static_cast<Tick>((kKtimeMax - largest - time_.host_ns_of(0)) / 250);
      }()),
      scheduler_(scheduler_hooks(), config.idle_ns, count_threads()) {
  time_.set_waiter(&bus_waiter_);
}

VirtualScheduler::Hooks VirtualHostTime::scheduler_hooks() {
  VirtualScheduler::Hooks h;
  DeviceBoard& board = board_;
  h.now = [&board] { return board.time().now(); };
  h.advance_to = [&board](Tick t) {
    board.advance_to(t);
    progress_time(t);
    fork_server_reached(t);  // `campaign`'s snapshots: the reruns injected at t fork here
    run_time_reached(t);  // `run --timeout`: the run ends at its simulated time limit
  };
  h.next_edge = [&board] { return board.next_edge_tick(); };
  h.next_world = [] { return std::min(run_next_tick(), fork_server_next_tick()); };
  h.fire_timer = [](int fd) { fire_virtual_timerfd(fd); };
  h.real_ns = [] { return real_clock_ns(CLOCK_MONOTONIC); };
  h.log = [](std::string_view line) { log_line(line); };
  h.inside_fd = [](int fd) { return inside_fd(fd); };
  h.describe_fd = [this](int fd) { return describe_fd(fd); };
  h.outside_wakeup = [] { return armed_real_timers(); };
  h.describe_board = [this] { return describe_board(); };
  h.deadlock = [this](const std::string& report) { end_deadlocked(report); };
  // Last, so that the closures above keep their names (linux/preload/hot_path.order lists some).
  h.time_limit = [] { return run_time_limit(); };
  // (Later still.) `run`'s view across processes: what this process waits on while only another
  // process can end a wait.
  h.stuck = [](const std::vector<int>& fds, bool other, const std::vector<std::string>& threads) {
    if (!run_publishes_waits()) return;
    ProcessWaits waits;
    for (const int fd : fds) waits.dependencies.push_back(dependency_of(fd));
    if (other) waits.dependencies.emplace_back();
    waits.threads = threads;
    run_publish_waits(format_process_waits(waits));
  };
  h.unstuck = [] { run_withdraw_waits(); };
  return h;
}

std::string VirtualHostTime::describe_fd(int fd) const {
  const std::string n = "fd " + std::to_string(fd);
  if (const FdEntry* e = fd_entry(fd)) {
    const std::vector<DeviceNode>& all = nodes();
    const std::string node = e->node < all.size() ? all[e->node].path : std::string("a gpiochip");
    if (e->kind == HandleKind::line_event_v1) return n + " (a v1 line event request on " + node + ")";
    if (e->kind == HandleKind::line_request_v2) return n + " (a line request on " + node + ")";
    return n + " (" + node + ")";
  }
  if (pipe_held_by_this_process_alone(fd)) return n + " (a pipe no other process holds)";
  if (socket_pair_held_by_this_process_alone(fd)) return n + " (a socket pair no other process holds)";
  if (const pid_t child = pidfd_child(fd); child > 0) return n + " (child " + std::to_string(child) + ")";
  bool armed = false;
  if (is_virtual_timerfd(fd, &armed)) return n + (armed ? " (a timerfd)" : " (a timerfd that is not armed)");
  std::vector<int> members;
  if (epoll_members(fd, members)) {
    std::string set = n + " (an epoll set of";
    for (std::size_t i = 0; i < members.size(); ++i) set += (i ? ", " : " ") + describe_fd(members[i]);
    return set + (members.empty() ? " nothing)" : ")");
  }
  return n;
}

std::string VirtualHostTime::describe_board() {
  std::string out;
  for (std::size_t c = 0; c < board_.chain_count(); ++c) {
    const ChipNumbering numbering = board_.chip_numbering(c);
    std::string line = board_.chain_summary(c) + ":";
    for (std::size_t k = 0; k < board_.chip_count(c); ++k) {
      const bool busy_high = board_.pin_level(c, k, Pin::BUSY), flag_high = board_.pin_level(c, k, Pin::FLAG);
      line += std::string(k ? ";" : "") + " " + numbering.label(k) + " BUSY " +
              (busy_high ? "high (no command running)" : "low (busy)") + ", FLAG " + (flag_high ? "high" : "low (alarm)");
    }
    out += line + "\n";
  }
  const std::string handles = board_.describe_handles();
  std::size_t at = 0;
  while (at < handles.size()) {
    const std::size_t nl = std::min(handles.find('\n', at), handles.size());
    const std::string l = handles.substr(at, nl - at);
    if (l.find(" line ") != std::string::npos) out += l + "\n";  // the gpio lines requested
    at = nl + 1;
  }
  if (board_.next_edge_tick() == kNever) out += "no BUSY or FLAG edge is to come on a line with edge events\n";
  return out;
}

void VirtualHostTime::end_deadlocked(const std::string& report) {
  end_run(RunEnd::deadlock, report);  // `l6470emu run` learns the cause from its report, not from the status
  // The report on standard error (as a sanitizer's; under `l6470emu run`, run prints it from the
  // run's report, once), and in the log file when there is one.
  if (!run_reads_report()) write_stderr_lines(report);
  if (!log_is_stderr()) {
    std::size_t at = 0;
    while (at <= report.size()) {
      const std::size_t nl = std::min(report.find('\n', at), report.size());
      log_line(report.substr(at, nl - at));
      at = nl + 1;
    }
  }
  // Nothing recorded is lost: traces are finished (a gzip trace gets its end), the program's
  // standard output and error buffers written.
  for (std::size_t c = 0; c < board_.chain_count(); ++c) board_.stop_recording(c);
  finish_coverage();
  for (FILE* f : {stdout, stderr})  // (a stream another thread holds locked is left as it is)
    if (ftrylockfile(f) == 0) {
      fflush_unlocked(f);
      funlockfile(f);
    }
  _exit(kDeadlockExitStatus);
}

VirtualHostTime::~VirtualHostTime() { time_.set_waiter(nullptr); }

bool VirtualHostTime::is_virtual_clock(clockid_t clock) {
  switch (clock) {
    case CLOCK_MONOTONIC:
    case CLOCK_MONOTONIC_RAW:
    case CLOCK_MONOTONIC_COARSE:
    case CLOCK_BOOTTIME:
    case CLOCK_BOOTTIME_ALARM:
    case CLOCK_REALTIME:
    case CLOCK_REALTIME_COARSE:
    case CLOCK_REALTIME_ALARM:
    case CLOCK_TAI:
      return true;
    default:
      return false;
  }
}

std::int64_t VirtualHostTime::offset_ns(clockid_t clock) const {
  switch (clock) {
    case CLOCK_BOOTTIME:
    case CLOCK_BOOTTIME_ALARM:
      return boottime_offset_ns_;
    case CLOCK_REALTIME:
    case CLOCK_REALTIME_COARSE:
    case CLOCK_REALTIME_ALARM:
      return time_.realtime_offset_ns();
    case CLOCK_TAI:
      return time_.realtime_offset_ns() + tai_offset_ns_;
    default:
      return 0;  // the MONOTONIC family
  }
}

std::int64_t VirtualHostTime::ns_at(clockid_t clock, Tick tick) const {
  if (tick > last_tick_) return kKtimeMax;  // saturated, never wrapped
  return time_.host_ns_of(tick) + offset_ns(clock);
}

std::int64_t VirtualHostTime::now_ns(clockid_t clock) const { return ns_at(clock, time_.now()); }

Tick VirtualHostTime::tick_at(clockid_t clock, std::int64_t ns) const {
  const std::int64_t offset = offset_ns(clock);
  // A deadline past the last time this clock can show is no deadline (a saturated kernel timer).
  if (ns > ns_at(clock, last_tick_)) return kNever;
  const std::int64_t monotonic = offset > 0 && ns < INT64_MIN + offset ? INT64_MIN : ns - offset;
  Tick t = time_.tick_of(monotonic);
  if (time_.host_ns_of(t) < monotonic) ++t;  // never wake before the deadline
  return t;
}

Tick VirtualHostTime::tick_after(std::int64_t ns) const {
  const Tick now = time_.now();
  if (ns <= 0) return now;
  const Tick ticks = static_cast<Tick>(ns / 250 + (ns % 250 != 0 ? 1 : 0));
  if (now >= last_tick_ || ticks > last_tick_ - now) return kNever;  // past the end of time: no deadline
  return now + ticks;
}

Tick VirtualHostTime::first_event_tick(int fd) const {
  // Both record layouts (struct gpioevent_data, struct gpio_v2_line_event) start with the
  // 64-bit timestamp; a peek of 8 bytes leaves the record queued.
  std::uint64_t stamp = 0;
  if (::recv(fd, &stamp, sizeof stamp, MSG_PEEK | MSG_DONTWAIT) != static_cast<ssize_t>(sizeof stamp)) return kNever;
  auto ns = static_cast<std::int64_t>(stamp);
  // A line asked for REALTIME stamps (GPIO_V2_LINE_FLAG_EVENT_CLOCK_REALTIME): in virtual mode
  // REALTIME is MONOTONIC plus a fixed offset of decades, far above any monotonic stamp.
  const std::int64_t realtime = time_.realtime_offset_ns();
  if (realtime > 0 && ns >= realtime) ns -= realtime;
  return tick_at(CLOCK_MONOTONIC, ns);
}

VirtualScheduler::End VirtualHostTime::wait(const VirtualScheduler::Wait& w) {
  t_looks = 0;
  if (w.call == nullptr && w.fds.size() == 1 && is_emulated_line(w.fds[0].fd)) {
    // The one covered wait that does not name itself: read() of a line request (intercept_io).
    VirtualScheduler::Wait named = w;
    named.call = "read";
    return scheduler_.wait(named);
  }
  return scheduler_.wait(w);
}

void VirtualHostTime::look() {
  if (++t_looks <= kSpinLooks) return;
  const std::int64_t doublings = std::min<std::int64_t>((t_looks - kSpinLooks - 1) / kLooksPerDoubling, 12);
  if (doublings == 12) t_looks = kSpinLooks + 12 * kLooksPerDoubling;  // no overflow in a long spin
  const Tick quantum = std::min(kFirstQuantum << doublings, kLastQuantum);
  VirtualScheduler::Wait w;
  w.call = "a busy-wait quantum";
  w.deadline = time_.now() + quantum;
  w.interruptible = false;
  int cancel_state;  // a clock read is no cancellation point
  pthread_setcancelstate(PTHREAD_CANCEL_DISABLE, &cancel_state);
  scheduler_.wait(w);
  pthread_setcancelstate(cancel_state, nullptr);
}

void VirtualHostTime::unlook() {
  if (t_looks > 0) --t_looks;
}

void VirtualHostTime::BusWaiter::wait_until(Tick tick) {
  VirtualScheduler::Wait w;
  w.call = "a spidev transfer's bus time";
  w.deadline = tick;
  w.interruptible = false;  // a spidev transfer finishes whatever signal arrives
  int cancel_state;          // and ioctl is no cancellation point
  pthread_setcancelstate(PTHREAD_CANCEL_DISABLE, &cancel_state);
  while (vt_.time_.now() < tick) vt_.wait(w);  // (pthread_cancel ends covered waits early)
  pthread_setcancelstate(cancel_state, nullptr);
}

void VirtualHostTime::before_fork() {
  scheduler_.before_fork();
  thread_table_before_fork();
  timerfd_table_before_fork();
}

void VirtualHostTime::after_fork_parent() {
  timerfd_table_after_fork();
  thread_table_after_fork();
  scheduler_.after_fork_parent();
}

void VirtualHostTime::after_fork_child() {
  mutex_waiters_after_fork_child();
  timerfd_table_after_fork();
  thread_table_after_fork();
  scheduler_.after_fork_child();
}

void VirtualHostTime::after_snapshot_fork_child() {
  scheduler_.renew_wake_fd();
  timerfd_table_after_snapshot();
}

void install_virtual_time(VirtualHostTime* vt) {
  init_thread_tracking();
  detail::g_virtual_time.store(vt, std::memory_order_release);
}

}  // namespace l6470emu::preload
