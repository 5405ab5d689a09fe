// select, pselect, poll, ppoll (and _chk variants), epoll_wait/_pwait/_pwait2 with their timeouts on
// virtual time, and waits on emulated gpio lines that end at the board's next edge (an event is
// not readable before its tick; epoll may see it one message early). Wall mode: the C library's.
#include <errno.h>
#include <poll.h>
#include <sys/epoll.h>
#include <sys/select.h>

#include <algorithm>
#include <vector>

#include "linux/preload/real.hpp"
#include "linux/preload/virtual_time.hpp"

using namespace l6470emu;
using namespace l6470emu::preload;
using End = VirtualScheduler::End;

namespace {

constexpr std::int64_t kNsPerMs = 1'000'000;

// epoll sets that had an emulated line added (indexed by the epoll descriptor).
constexpr int kEpollTable = 1 << 16;
std::atomic<bool> g_epoll_has_lines[kEpollTable];

// Timeouts as the kernel takes them: timespec64_valid, then saturated at KTIME_MAX (a timeout
// that reaches it never ends).
bool valid(const timespec& ts) { return kernel_valid(ts); }
std::int64_t to_ns(const timespec& ts) { return saturated_ns(ts); }

// select()'s timeval as glibc and the kernel take it: negative fields are EINVAL (false), and
// microseconds of a second or more carry into the seconds; saturated at KTIME_MAX.
bool select_timeout_ns(const timeval& tv, std::int64_t& ns) {
  if (tv.tv_sec < 0 || tv.tv_usec < 0) return false;
  const std::int64_t carry = tv.tv_usec / 1'000'000;
  const std::int64_t sec = tv.tv_sec > INT64_MAX - carry ? INT64_MAX : tv.tv_sec + carry;
  ns = saturated_ns(timespec{static_cast<time_t>(sec), static_cast<long>(tv.tv_usec % 1'000'000 * 1000)});
  return true;
}

bool any_emulated_line(const pollfd* fds, nfds_t n) {
  for (nfds_t i = 0; i < n; ++i)
    if (is_emulated_line(fds[i].fd)) return true;
  return false;
}

// Readiness as a zero-timeout poll reports it, except that an emulated line whose first event
// lies in the program's future is not readable yet: its POLLIN is cleared, `future[i]` set, and
// `later` lowered to that event's tick. Returns the count (or -1 with errno).
int ready_now(VirtualHostTime& vt, pollfd* fds, nfds_t n, const sigset_t* mask, std::vector<char>& future,
              Tick& later) {
  const timespec zero{0, 0};
  future.assign(n, 0);
  int r = real::ppoll(fds, n, &zero, mask);
  if (r <= 0) return r;
  const Tick now = vt.tick_after(0);
  for (nfds_t i = 0; i < n; ++i) {
    if (!(fds[i].revents & POLLIN) || !is_emulated_line(fds[i].fd)) continue;
    const Tick t = vt.first_event_tick(fds[i].fd);
    if (t == kNever || t <= now) continue;
    fds[i].revents &= static_cast<short>(~(POLLIN | POLLRDNORM));
    future[i] = 1;
    later = std::min(later, t);
    if (fds[i].revents == 0) --r;
  }
  return r;
}

// poll/ppoll with a timeout (ns, < 0 = none) on virtual time.
int virtual_poll(VirtualHostTime& vt, pollfd* fds, nfds_t n, std::int64_t timeout_ns, const sigset_t* mask,
                 const char* call) {
  std::vector<char> future;
  Tick later = kNever;
  if (timeout_ns == 0) vt.look();
  int r = ready_now(vt, fds, n, mask, future, later);
  if (r != 0 || timeout_ns == 0) return r;
  const Tick deadline = timeout_ns < 0 ? kNever : vt.tick_after(timeout_ns);
  const bool board = any_emulated_line(fds, n);
  std::vector<pollfd> watch(fds, fds + n);
  for (;;) {
    // A line whose next event is already queued (for later) is waited for by its tick instead.
    for (nfds_t i = 0; i < n; ++i) watch[i].events = future[i] ? 0 : fds[i].events;
    VirtualScheduler::Wait w;
    w.call = call;
    w.deadline = std::min(deadline, later);
    w.timeout_beyond_end = timeout_ns >= 0 && w.deadline == kNever;
    w.fds = watch;
    w.watches_board = board;
    w.sigmask = mask;
    if (vt.wait(w) == End::interrupted) {
      errno = EINTR;
      return -1;
    }
    later = kNever;
    r = ready_now(vt, fds, n, nullptr, future, later);
    if (r != 0 || vt.tick_after(0) >= deadline) return r;
    // Not ready yet (or ready a moment ago and taken by another thread): wait on.
  }
}

// select/pselect on virtual time, through poll: the sets become pollfds, and the result the sets
// the kernel's select would give (read: IN/HUP/ERR, write: OUT/ERR, except: PRI).
// `remaining` (select's timeval) gets the time left.
int virtual_select(VirtualHostTime& vt, int nfds, fd_set* r, fd_set* w, fd_set* e, std::int64_t timeout_ns,
                   const sigset_t* mask, timeval* remaining, const char* call) {
  std::vector<pollfd> fds;
  for (int fd = 0; fd < nfds && fd < FD_SETSIZE; ++fd) {
    short events = 0;
    if (r && FD_ISSET(fd, r)) events |= POLLIN;
    if (w && FD_ISSET(fd, w)) events |= POLLOUT;
    if (e && FD_ISSET(fd, e)) events |= POLLPRI;
    if (events) fds.push_back({fd, events, 0});
  }
  const Tick start = vt.tick_after(0);
  const int n = virtual_poll(vt, fds.data(), fds.size(), timeout_ns, mask, call);
  if (remaining && timeout_ns > 0) {
    const std::int64_t used = static_cast<std::int64_t>(std::min<Tick>(vt.tick_after(0) - start, kKtimeMax / 250)) * 250;
    const std::int64_t left = timeout_ns > used ? timeout_ns - used : 0;
    remaining->tv_sec = static_cast<time_t>(left / 1'000'000'000);
    remaining->tv_usec = static_cast<suseconds_t>(left % 1'000'000'000 / 1000);
  }
  if (n < 0) return n;
  for (const pollfd& p : fds)
    if (p.revents & POLLNVAL) {
      errno = EBADF;
      return -1;
    }
  if (r) FD_ZERO(r);
  if (w) FD_ZERO(w);
  if (e) FD_ZERO(e);
  int count = 0;
  for (const pollfd& p : fds) {
    if (r && (p.events & POLLIN) && (p.revents & (POLLIN | POLLHUP | POLLERR))) FD_SET(p.fd, r), ++count;
    if (w && (p.events & POLLOUT) && (p.revents & (POLLOUT | POLLERR))) FD_SET(p.fd, w), ++count;
    if (e && (p.events & POLLPRI) && (p.revents & POLLPRI)) FD_SET(p.fd, e), ++count;
  }
  return count;
}

int virtual_epoll(VirtualHostTime& vt, int epfd, epoll_event* events, int max, std::int64_t timeout_ns,
                  const sigset_t* mask, const char* call) {
  if (timeout_ns == 0) {
    vt.look();
    return real::epoll_pwait(epfd, events, max, 0, mask);
  }
  int n = real::epoll_pwait(epfd, events, max, 0, mask);
  if (n != 0) return n;
  // An epoll set is readable when one of its descriptors is ready.
  const pollfd set{epfd, POLLIN, 0};
  VirtualScheduler::Wait w;
  w.call = call;
  w.deadline = timeout_ns < 0 ? kNever : vt.tick_after(timeout_ns);
  w.timeout_beyond_end = timeout_ns >= 0 && w.deadline == kNever;
  w.fds = std::span<const pollfd>(&set, 1);
  w.watches_board = epfd >= 0 && epfd < kEpollTable && g_epoll_has_lines[epfd].load(std::memory_order_relaxed);
  w.sigmask = mask;
  for (;;) {
    const End end = vt.wait(w);
    if (end == End::interrupted) {
      errno = EINTR;
      return -1;
    }
    n = real::epoll_pwait(epfd, events, max, 0, nullptr);
    if (n != 0 || end == End::timed_out) return n;
  }
}

}  // namespace

namespace l6470emu::preload {

bool is_emulated_line(int fd) {
  const FdEntry* e = fd_entry(fd);
  return e && (e->kind == HandleKind::line_event_v1 || e->kind == HandleKind::line_request_v2);
}

}  // namespace l6470emu::preload

extern "C" {

void __chk_fail(void) __attribute__((noreturn));

__attribute__((visibility("default"))) int poll(struct pollfd* fds, nfds_t n, int timeout_ms) {
  VirtualHostTime* vt = virtual_time();
  if (!vt) return real::poll(fds, n, timeout_ms);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return virtual_poll(*vt, fds, n, timeout_ms < 0 ? -1 : timeout_ms * kNsPerMs, nullptr, "poll");
    } catch (...) {
      return real::poll(fds, n, timeout_ms);
    }
  });
}

__attribute__((visibility("default"))) int __poll_chk(struct pollfd* fds, nfds_t n, int timeout_ms, size_t fdslen) {
  if (fdslen / sizeof(*fds) < n) __chk_fail();
  return poll(fds, n, timeout_ms);
}

__attribute__((visibility("default"))) int ppoll(struct pollfd* fds, nfds_t n, const struct timespec* timeout,
                                                 const sigset_t* mask) {
  VirtualHostTime* vt = virtual_time();
  if (!vt || (timeout && !valid(*timeout))) return real::ppoll(fds, n, timeout, mask);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return virtual_poll(*vt, fds, n, timeout ? to_ns(*timeout) : -1, mask, "ppoll");
    } catch (...) {
      return real::ppoll(fds, n, timeout, mask);
    }
  });
}

__attribute__((visibility("default"))) int __ppoll_chk(struct pollfd* fds, nfds_t n, const struct timespec* timeout,
                                                       const sigset_t* mask, size_t fdslen) {
  if (fdslen / sizeof(*fds) < n) __chk_fail();
  return ppoll(fds, n, timeout, mask);
}

__attribute__((visibility("default"))) int select(int nfds, fd_set* r, fd_set* w, fd_set* e, struct timeval* timeout) {
  VirtualHostTime* vt = virtual_time();
  std::int64_t ns = -1;
  if (!vt || nfds < 0 || (timeout && !select_timeout_ns(*timeout, ns))) return real::select(nfds, r, w, e, timeout);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return virtual_select(*vt, nfds, r, w, e, ns, nullptr, timeout, "select");
    } catch (...) {
      return real::select(nfds, r, w, e, timeout);
    }
  });
}

__attribute__((visibility("default"))) int pselect(int nfds, fd_set* r, fd_set* w, fd_set* e,
                                                   const struct timespec* timeout, const sigset_t* mask) {
  VirtualHostTime* vt = virtual_time();
  if (!vt || nfds < 0 || (timeout && !valid(*timeout))) return real::pselect(nfds, r, w, e, timeout, mask);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return virtual_select(*vt, nfds, r, w, e, timeout ? to_ns(*timeout) : -1, mask, nullptr, "pselect");
    } catch (...) {
      return real::pselect(nfds, r, w, e, timeout, mask);
    }
  });
}

__attribute__((visibility("default"))) int epoll_wait(int epfd, struct epoll_event* events, int max, int timeout_ms) {
  VirtualHostTime* vt = virtual_time();
  if (!vt || max <= 0) return real::epoll_wait(epfd, events, max, timeout_ms);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return virtual_epoll(*vt, epfd, events, max, timeout_ms < 0 ? -1 : timeout_ms * kNsPerMs, nullptr, "epoll_wait");
    } catch (...) {
      return real::epoll_wait(epfd, events, max, timeout_ms);
    }
  });
}

__attribute__((visibility("default"))) int epoll_pwait(int epfd, struct epoll_event* events, int max, int timeout_ms,
                                                       const sigset_t* mask) {
  VirtualHostTime* vt = virtual_time();
  if (!vt || max <= 0) return real::epoll_pwait(epfd, events, max, timeout_ms, mask);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return virtual_epoll(*vt, epfd, events, max, timeout_ms < 0 ? -1 : timeout_ms * kNsPerMs, mask, "epoll_pwait");
    } catch (...) {
      return real::epoll_pwait(epfd, events, max, timeout_ms, mask);
    }
  });
}

__attribute__((visibility("default"))) int epoll_pwait2(int epfd, struct epoll_event* events, int max,
                                                        const struct timespec* timeout, const sigset_t* mask) {
  VirtualHostTime* vt = virtual_time();
  if (!vt || max <= 0 || (timeout && !valid(*timeout))) return real::epoll_pwait2(epfd, events, max, timeout, mask);
  return as_cancellation_point([&]() __attribute__((noinline)) -> int {
    Guard guard;
    try {
      return virtual_epoll(*vt, epfd, events, max, timeout ? to_ns(*timeout) : -1, mask, "epoll_pwait2");
    } catch (...) {
      return real::epoll_pwait2(epfd, events, max, timeout, mask);
    }
  });
}

__attribute__((visibility("default"))) int epoll_ctl(int epfd, int op, int fd, struct epoll_event* event) noexcept {
  const int r = real::epoll_ctl(epfd, op, fd, event);
  if (r == 0 && op == EPOLL_CTL_ADD && epfd >= 0 && epfd < kEpollTable && installed_virtual_time() && is_emulated_line(fd))
    g_epoll_has_lines[epfd].store(true, std::memory_order_relaxed);
  return r;
}

}  // extern "C"
