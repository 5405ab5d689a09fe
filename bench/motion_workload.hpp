// The motion workload the benchmarks share: a chain of chips each running a random
// (fixed-seed) Move/Run profile while a host polls GetStatus of every chip every 1 ms of
// simulated time over a 5 MHz bus. Used by motion_bench.cpp and headline.cpp.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "core/fast_motion.hpp"
#include "daisychain/chain.hpp"
#include "spi/message.hpp"

namespace l6470emu::bench {

/// Which motion engine the chips run; every benchmark is registered once per engine so the
/// rows compare side by side. A further engine = one more case here and one more registration.
using Engine = MotionEngine;

constexpr const char* engine_name(Engine e) {
  switch (e) {
    case Engine::reference: return "reference";
    case Engine::fast: return "fast";
  }
  return "?";
}

/// A chain of `n` default L6470s whose chips use `engine` (set explicitly: the default may change).
Chain make_chain(std::size_t n, Engine engine) {
  Chain chain(n);
  chain.set_motion_engine(engine);
  return chain;
}

/// The mechanics each chip gets when a workload runs with axes: a default NEMA-17 with a light
/// load, hard stops and a switch far out (so every jump also looks for position events) and
/// the chip's reset KVAL/BEMF registers, so fast profiles lose steps and stall as they would.
inline AxisSpec bench_axis() {
  AxisSpec spec;
  spec.load.friction_uNm = 10'000;
  spec.load.inertia_g_mm2 = 5'000;
  spec.has_lower_stop = spec.has_upper_stop = true;
  spec.lower_stop = -(std::int64_t{1} << 30);
  spec.upper_stop = std::int64_t{1} << 30;
  SwitchSpec home;
  home.position = -(std::int64_t{1} << 29);
  home.hysteresis = 16;
  spec.switches.push_back(home);
  return spec;
}

/// Host-side view of one axis: what the host last told it to do, and what it waits for.
struct Axis {
  enum class Phase : std::uint8_t { idle, moving, running, stopping } phase = Phase::idle;
  Tick run_until = 0;  ///< running: when to send SoftStop
  // The next step is due when (STATUS & wake_mask) == wake_value or at wake_at (kNever: no
  // time): the phase's condition below, kept so that a poll that changes nothing costs little.
  std::uint16_t wake_mask = 0, wake_value = 0;
  Tick wake_at = kNever;
};

/// What the host saw; lets a benchmark show that the motors really moved.
struct MotionStats {
  std::uint64_t polls = 0;        ///< GetStatus rounds (every chip polled once)
  std::uint64_t frames = 0;       ///< CS frames on the bus
  std::uint64_t commands = 0;     ///< Move / Run / SoftStop commands sent
  std::uint64_t moves_done = 0;   ///< Moves seen finished (BUSY released)
  std::uint64_t runs_done = 0;    ///< Runs seen stopped after their SoftStop
  std::uint64_t cmd_errors = 0;   ///< polls showing NOTPERF_CMD or WRONG_CMD (should stay 0)
};

/// 64 (or N) chips behind one chip-select; a host that polls every chip every 1 ms of
/// simulated time and, from what STATUS says, gives each idle axis a random Move or Run
/// (Runs end with SoftStop after a random time). Bus: 5 MHz SCK, 1 us CS high; every CS
/// frame advances the chain by its own duration before its bytes are decoded.
class MotionWorkload {
 public:
  static constexpr Tick kPollPeriod = ticks_from_ms(1);
  static constexpr std::uint32_t kSckHz = 5'000'000;

  /// With `axes`, every chip has bench_axis() behind it.
  MotionWorkload(std::size_t chips, Engine engine, std::uint64_t seed = 0x6470, bool axes = false)
      : chain_(make_chain(chips, engine)),
        rng_(seed),
        axes_(chips),
        status_(chips),
        rx_(chips),
        msb_(chips),
        get_status_(chips, 0xD0),
        nops_(chips, 0x00),
        frame_ticks_(transfer_ticks(static_cast<std::uint32_t>(chips), kSckHz) + BusTiming{}.cs_high_ticks) {
    for (auto& f : cmd_) f.assign(chips, 0x00);
    if (axes)
      for (std::size_t k = 0; k < chips; ++k) chain_.chip(k).attach_axis(bench_axis());
    const StatusLayout& layout = chain_.chip(0).variant().status;
    busy_bit_ = 1u << layout.busy;
    mot_shift_ = static_cast<unsigned>(layout.mot_status);
    error_bits_ = (1u << layout.notperf_cmd) | (1u << layout.wrong_cmd);
    setup_profiles();
    next_poll_ = chain_.now();  // first poll at once; it also clears the power-up UVLO latch
  }

  /// Runs exactly `ms` milliseconds of simulated time: a poll (and the commands it leads to)
  /// at the start of each ms. Calls compose: run_ms(a) then run_ms(b) is run_ms(a + b).
  /// (Exact while the frames of one ms fit in it: 64 chips at 5 MHz need at most 0.7 ms.)
  void run_ms(std::uint64_t ms) {
    for (std::uint64_t i = 0; i < ms; ++i) {
      chain_.advance_to(next_poll_);
      poll();
      command_round();
      next_poll_ += kPollPeriod;
    }
    chain_.advance_to(next_poll_);
  }

  Tick now() const { return chain_.now(); }
  const MotionStats& stats() const { return stats_; }
  std::size_t chips() const { return chain_.size(); }
  const Chain& chain() const { return chain_; }

 private:
  using Bytes = std::vector<std::uint8_t>;

  /// One CS frame: the bytes take their time on the bus, then CS rises and the chips decode.
  void frame(const Bytes& tx, Bytes& rx) {
    chain_.advance_to(chain_.now() + frame_ticks_);
    chain_.select();
    chain_.exchange(tx, rx);
    chain_.deselect();
    ++stats_.frames;
  }

  /// Random ACC, DEC and MAX_SPEED for every chip (SetParam through the chain, 3 frames each).
  void setup_profiles() {
    struct Param { std::uint8_t address; std::uint32_t lo, hi; };
    // ACC/DEC 0x020..0x400: ~470..14900 step/s²; MAX_SPEED 0x020..0x120: ~490..4400 step/s.
    constexpr std::array<Param, 3> params{{{0x05, 0x020, 0x400}, {0x06, 0x020, 0x400}, {0x07, 0x020, 0x120}}};
    max_speed_.assign(chips(), 0);
    for (const Param& p : params) {
      std::uniform_int_distribution<std::uint32_t> dist(p.lo, p.hi);
      Bytes addr(chips(), p.address), hi(chips()), lo(chips());
      for (std::size_t k = 0; k < chips(); ++k) {
        const std::uint32_t v = dist(rng_);
        hi[k] = static_cast<std::uint8_t>(v >> 8);
        lo[k] = static_cast<std::uint8_t>(v);
        if (p.address == 0x07) max_speed_[k] = v;
      }
      frame(addr, rx_);
      frame(hi, rx_);
      frame(lo, rx_);
    }
  }

  /// GetStatus to every chip: 0xD0 x N, then two NOP frames carrying STATUS MSB and LSB.
  void poll() {
    frame(get_status_, rx_);
    frame(nops_, msb_);
    frame(nops_, rx_);
    for (std::size_t k = 0; k < chips(); ++k) status_[k] = static_cast<std::uint16_t>(msb_[k] << 8 | rx_[k]);
    ++stats_.polls;
  }

  /// Decides from the polled STATUS what each axis does next and sends all commands in
  /// one round of frames, right-aligned (shorter commands padded with NOPs in front).
  void command_round() {
    std::size_t longest = 0;
    const std::size_t n = chips();
    const Tick now = chain_.now();
    std::uint64_t errors = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const std::uint16_t st = status_[k];
      errors += (st & error_bits_) != 0;
      const Axis& a = axes_[k];
      if ((st & a.wake_mask) == a.wake_value || now >= a.wake_at) longest = std::max(longest, next_step(k, st));
    }
    stats_.cmd_errors += errors;
    if (longest == 0) return;
    for (std::size_t f = cmd_.size() - longest; f < cmd_.size(); ++f) {
      frame(cmd_[f], rx_);
      std::fill(cmd_[f].begin(), cmd_[f].end(), 0x00);
    }
  }

  /// What axis k does on STATUS `st` (the axis's wake condition holds); returns the length of
  /// the command it queued, 0 for none.
  std::size_t next_step(std::size_t k, std::uint16_t st) {
    const bool busy = (st & busy_bit_) == 0;  // BUSY is active low
    const bool stopped = ((st >> mot_shift_) & 3u) == 0;
    std::size_t longest = 0;
    Axis& a = axes_[k];
    switch (a.phase) {
      case Axis::Phase::moving:
        if (!busy) { ++stats_.moves_done; set_phase(a, Axis::Phase::idle); }
        break;
      case Axis::Phase::running:
        if (chain_.now() >= a.run_until) {
          longest = put_command(k, {0xB0});  // SoftStop
          set_phase(a, Axis::Phase::stopping);
        }
        break;
      case Axis::Phase::stopping:
        if (!busy && stopped) { ++stats_.runs_done; set_phase(a, Axis::Phase::idle); }
        break;
      case Axis::Phase::idle:
        break;
    }
    if (a.phase == Axis::Phase::idle) longest = std::max(longest, start_random_motion(k));
    return longest;
  }

  /// Enters `phase` with its wake condition: a Move ends when BUSY is released, a Run is
  /// stopped at run_until, a stop ends when BUSY is released with MOT_STATUS stopped, and an
  /// idle axis gets a new motion at once.
  void set_phase(Axis& a, Axis::Phase phase) const {
    a.phase = phase;
    a.wake_at = kNever;
    switch (phase) {
      case Axis::Phase::idle: a.wake_mask = a.wake_value = 0; break;
      case Axis::Phase::moving: a.wake_mask = a.wake_value = busy_bit_; break;
      case Axis::Phase::running: a.wake_mask = 0, a.wake_value = 1, a.wake_at = a.run_until; break;
      case Axis::Phase::stopping:
        a.wake_mask = static_cast<std::uint16_t>(busy_bit_ | 3u << mot_shift_);
        a.wake_value = busy_bit_;
        break;
    }
  }

  /// Queues a random Move (2000..200000 microsteps) or Run (1/8..1 of MAX_SPEED for 20..300 ms).
  std::size_t start_random_motion(std::size_t k) {
    Axis& a = axes_[k];
    const bool forward = std::uniform_int_distribution<int>(0, 1)(rng_) == 1;
    if (std::uniform_int_distribution<int>(0, 1)(rng_) == 0) {
      const std::uint32_t steps = std::uniform_int_distribution<std::uint32_t>(2'000, 200'000)(rng_);
      set_phase(a, Axis::Phase::moving);
      return put_command(k, {static_cast<std::uint8_t>(0x40 | forward), steps});
    }
    const std::uint32_t top = max_speed_[k] << 10;  // MAX_SPEED in SPEED units (2^-28 step/tick)
    const std::uint32_t spd = std::uniform_int_distribution<std::uint32_t>(top / 8, top)(rng_);
    a.run_until = chain_.now() + ticks_from_ms(std::uniform_int_distribution<std::uint64_t>(20, 300)(rng_));
    set_phase(a, Axis::Phase::running);
    return put_command(k, {static_cast<std::uint8_t>(0x50 | forward), spd});
  }

  /// An opcode and an optional 3-byte argument, MSB first.
  struct Command {
    std::uint8_t opcode;
    std::uint32_t arg = 0;
    bool has_arg = true;
    Command(std::uint8_t op) : opcode(op), has_arg(false) {}
    Command(std::uint8_t op, std::uint32_t a) : opcode(op), arg(a) {}
  };

  /// Puts chip k's command at the end of the round's frames; returns its length in bytes.
  std::size_t put_command(std::size_t k, Command c) {
    ++stats_.commands;
    const std::size_t last = cmd_.size() - 1;
    if (!c.has_arg) {
      cmd_[last][k] = c.opcode;
      return 1;
    }
    cmd_[last - 3][k] = c.opcode;
    cmd_[last - 2][k] = static_cast<std::uint8_t>(c.arg >> 16);
    cmd_[last - 1][k] = static_cast<std::uint8_t>(c.arg >> 8);
    cmd_[last][k] = static_cast<std::uint8_t>(c.arg);
    return 4;
  }

  Chain chain_;
  std::mt19937_64 rng_;
  std::vector<Axis> axes_;
  std::vector<std::uint32_t> max_speed_;
  std::vector<std::uint16_t> status_;
  Bytes rx_, msb_, get_status_, nops_;
  std::array<Bytes, 4> cmd_;  // one command round: up to 4 frames
  Tick frame_ticks_;
  Tick next_poll_ = 0;
  std::uint16_t busy_bit_ = 0, error_bits_ = 0;
  unsigned mot_shift_ = 0;
  MotionStats stats_;
};

}  // namespace l6470emu::bench
