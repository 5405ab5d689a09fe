// The one owner of "what time is it for this board": the host's clocks as an interface (the
// kernel's are linux/clock.hpp's, a test or a firmware front brings its own), the mapping
// between the host's monotonic clock and the board's 250 ns ticks, and how a host waits until
// the board reaches a tick. No OS calls here; core/ never uses it.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>

#include "core/tick.hpp"
#include "board/board_config.hpp"

namespace l6470emu {

/// The host's clocks as the board reads them. The Linux front uses real_host_clock()
/// (linux/clock.hpp); tests inject their own so that the clock rules can be checked deterministically.
class HostClock {
 public:
  virtual ~HostClock() = default;
  /// CLOCK_MONOTONIC, ns.
  virtual std::int64_t monotonic_ns() = 0;
  /// CLOCK_MONOTONIC to within a few ms, cheaper to read (the kernel's CLOCK_MONOTONIC_COARSE):
  /// for choices made by the hundred milliseconds on every event, such as when a recording
  /// flushes. The same clock as monotonic_ns() unless a host has a cheaper one.
  virtual std::int64_t coarse_monotonic_ns() { return monotonic_ns(); }
  /// CLOCK_REALTIME, ns.
  virtual std::int64_t realtime_ns() = 0;
  /// Returns no earlier than CLOCK_MONOTONIC == `monotonic_ns` (at once when it has passed).
  virtual void sleep_until(std::int64_t monotonic_ns) = 0;
};

/// Where the host's CLOCK_MONOTONIC stands at tick 0 in virtual mode (ns): a fixed 1000 s, not
/// the real clock, so that a program's readings — and what it computes and prints from them,
/// down to the rounding of a float — are the same every run. REALTIME still starts at the real
/// time of the start.
inline constexpr std::int64_t kVirtualMonotonicOrigin = 1'000'000'000'000;

/// The board's time. Wall mode: tick = (host CLOCK_MONOTONIC - origin) × scale / 250 ns, and a
/// host thread waits for a tick by sleeping until the host time it maps to. Virtual mode: the
/// tick only moves when set_now() moves it (bus time, waits, `ctl advance`); the host's clocks
/// read as kVirtualMonotonicOrigin + tick × 250 ns, so host and board agree exactly in both modes.
class BoardTime {
 public:
  /// Something that makes a host thread wait for virtual time (the preload's scheduler).
  class Waiter {
   public:
    virtual ~Waiter() = default;
    /// Blocks the calling thread until the board's time reaches `tick` (it moves the time on
    /// itself when every thread of the program waits).
    virtual void wait_until(Tick tick) = 0;
  };

  /// Time as `config` says, on `host` (which must outlive this object).
  BoardTime(const TimeConfig& config, HostClock& host);

  bool is_virtual() const { return virtual_; }
  /// Virtual seconds per host second (wall mode; 1 in virtual mode).
  double scale() const { return scale_; }
  HostClock& host() const { return host_; }

  /// The board's tick now.
  Tick now() const;
  /// Blocks the calling host thread until the board's time is at least `tick`. Wall mode:
  /// sleeps (then spins) until host_ns_of(tick). Virtual mode: the installed Waiter decides;
  /// without one, the time simply moves on to `tick` (bus time is the only clock then).
  void wait_until(Tick tick);
  /// The host's CLOCK_MONOTONIC (ns) when the board is at `tick` (event timestamps).
  std::int64_t host_ns_of(Tick tick) const;
  /// The tick the board is at when the host's CLOCK_MONOTONIC reads `host_ns` (rounded down).
  Tick tick_of(std::int64_t host_ns) const;
  /// CLOCK_REALTIME minus CLOCK_MONOTONIC as the host sees it (REALTIME event timestamps).
  std::int64_t realtime_offset_ns() const;

  /// Virtual mode: moves the time to `tick` if it is later (never backwards). Returns now().
  /// The board's chains catch up lazily; Board::advance_to also emits their edges.
  Tick set_now(Tick tick);
  /// Virtual mode: who waits for time (nullptr: nobody; wait_until then just moves time).
  void set_waiter(Waiter* waiter) { waiter_.store(waiter, std::memory_order_release); }
  Waiter* waiter() const { return waiter_.load(std::memory_order_acquire); }

 private:
  HostClock& host_;
  bool virtual_;
  double scale_;
  std::int64_t origin_ns_;           // host CLOCK_MONOTONIC at tick 0
  std::int64_t realtime_offset_ns_;  // virtual mode: REALTIME - MONOTONIC at the start
  std::atomic<Tick> virtual_now_{0};
  std::atomic<Waiter*> waiter_{nullptr};
};

}  // namespace l6470emu
