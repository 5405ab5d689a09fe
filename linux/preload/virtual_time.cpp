// Virtual host time in the preload library: clock conversions, covered waits, the busy-wait
// rule, the board's bus-time waiter, fork hooks.
#include "linux/preload/virtual_time.hpp"

#include <dirent.h>
#include <pthread.h>
#include <sys/socket.h>

#include <algorithm>
#include <cstring>

#include "linux/preload/real.hpp"

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

VirtualScheduler::Hooks scheduler_hooks(DeviceBoard& board) {
  VirtualScheduler::Hooks h;
  h.now = [&board] { return board.time().now(); };
  h.advance_to = [&board](Tick t) { board.advance_to(t); };
  h.next_edge = [&board] { return board.next_edge_tick(); };
  h.fire_timer = [](int fd) { fire_virtual_timerfd(fd); };
  h.real_ns = [] { return real_clock_ns(CLOCK_MONOTONIC); };
  h.log = [](std::string_view line) { log_line(line); };
  return h;
}

}  // namespace

VirtualHostTime::VirtualHostTime(DeviceBoard& board, const TimeConfig& config)
    : board_(board),
      time_(board.time()),
      boottime_offset_ns_(real_clock_ns(CLOCK_BOOTTIME) - real_clock_ns(CLOCK_MONOTONIC)),
      tai_offset_ns_(real_clock_ns(CLOCK_TAI) - real_clock_ns(CLOCK_REALTIME)),
      scheduler_(scheduler_hooks(board), config.idle_ns, count_threads()) {
  time_.set_waiter(&bus_waiter_);
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

std::int64_t VirtualHostTime::ns_at(clockid_t clock, Tick tick) const { return time_.host_ns_of(tick) + offset_ns(clock); }

std::int64_t VirtualHostTime::now_ns(clockid_t clock) const { return ns_at(clock, time_.now()); }

Tick VirtualHostTime::tick_at(clockid_t clock, std::int64_t ns) const {
  const std::int64_t monotonic = ns - offset_ns(clock);
  Tick t = time_.tick_of(monotonic);
  if (time_.host_ns_of(t) < monotonic) ++t;  // never wake before the deadline
  return t;
}

Tick VirtualHostTime::tick_after(std::int64_t ns) const {
  const Tick now = time_.now();
  if (ns <= 0) return now;
  // A deadline that far away is no deadline.
  if (ns >= std::int64_t{1} << 62) return kNever;
  return now + static_cast<Tick>((ns + 249) / 250);
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
  return scheduler_.wait(w);
}

void VirtualHostTime::look() {
  if (++t_looks <= kSpinLooks) return;
  const std::int64_t doublings = std::min<std::int64_t>((t_looks - kSpinLooks - 1) / kLooksPerDoubling, 12);
  if (doublings == 12) t_looks = kSpinLooks + 12 * kLooksPerDoubling;  // no overflow in a long spin
  const Tick quantum = std::min(kFirstQuantum << doublings, kLastQuantum);
  VirtualScheduler::Wait w;
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
  timerfd_table_after_fork();
  thread_table_after_fork();
  scheduler_.after_fork_child();
}

void install_virtual_time(VirtualHostTime* vt) {
  init_thread_tracking();
  detail::g_virtual_time.store(vt, std::memory_order_release);
}

}  // namespace l6470emu::preload
