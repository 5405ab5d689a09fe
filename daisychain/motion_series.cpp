// sample_motion: walks a trace with a ProtocolTracker (so frames, pins and faults reach the
// chain exactly as in a replay) and, between events, steps the chain from one rule change of
// the motion engine to the next (core's uniform_ticks), so every MOT_STATUS and BUSY edge is
// sampled at its own tick; a regular grid adds the curve in between. Long runs are thinned
// per time slice afterwards.
#include "daisychain/motion_series.hpp"
#include "core/counted.hpp"

#include <algorithm>
#include <climits>
#include <cstdio>
#include <stdexcept>

#include "core/fast_motion.hpp"
#include "core/registers.hpp"
#include "daisychain/divergence.hpp"
#include "daisychain/explain.hpp"
#include "daisychain/protocol_tracker.hpp"

namespace l6470emu {
namespace {

/// The shortest window a chip without a SPEED register (the L6474) has its step rate averaged
/// over: 10 ms, ten pulses of a 1 kHz step clock.
constexpr Tick kMinRateWindow = kTicksPerSecond / 100;

/// Boundary-only stops allowed between two grid ticks before the rest are skipped (a rule
/// that changes every tick, as at the end of a stop, would otherwise cost a sample per tick).
constexpr int kBoundariesPerGridStep = 16;

bool listed_command(Command c) {
  return c != Command::NOP && c != Command::GetParam && c != Command::GetStatus;
}

MotionSample sample_of(const Chip& c, Tick t) {
  const MotionState& m = c.motion();
  MotionSample s;
  s.tick = t;
  s.abs_pos = m.abs_pos;
  const auto speed = static_cast<std::int32_t>(c.peek(Reg::SPEED));
  s.speed = m.dir ? speed : -speed;
  s.mot_status = static_cast<std::uint8_t>(motion_flags(m, c.profile()).mot);
  s.busy = c.busy_sync_pin();
  s.flag = c.flag_pin();
  s.sw = c.sw_pin();
  s.hiz = m.hiz;
  return s;
}

/// Keeps, per time slice, the first and last sample, those with the extremes of ABS_POS and
/// SPEED, and the first change of each pin and of MOT_STATUS within the slice.
std::vector<MotionSample> thin(const std::vector<MotionSample>& in, Tick from, Tick to, std::size_t max_points) {
  constexpr std::size_t kKeptPerSlice = 11;
  if (in.size() <= max_points) return in;
  const std::size_t slices = std::max<std::size_t>(1, max_points / kKeptPerSlice);
  const Tick span = std::max<Tick>(1, to - from);
  std::vector<MotionSample> out;
  out.reserve(max_points);
  auto slice_of = [&](Tick t) {
    const Tick into = t > from ? t - from : 0;
    return std::min<std::size_t>(slices - 1,
                                 static_cast<std::size_t>(static_cast<unsigned __int128>(into) * slices / span));
  };
  std::size_t i = 0;
  std::vector<std::size_t> keep;
  while (i < in.size()) {
    const std::size_t slice = slice_of(in[i].tick);
    std::size_t j = i;
    while (j < in.size() && slice_of(in[j].tick) == slice) ++j;
    // [i, j) is one slice.
    keep.assign({i, j - 1});
    std::size_t lo_pos = i, hi_pos = i, lo_speed = i, hi_speed = i;
    std::size_t busy = 0, flag = 0, sw = 0, hiz = 0, mot = 0;
    for (std::size_t k = i; k < j; ++k) {
      const MotionSample& s = in[k];
      if (s.abs_pos < in[lo_pos].abs_pos) lo_pos = k;
      if (s.abs_pos > in[hi_pos].abs_pos) hi_pos = k;
      if (s.speed < in[lo_speed].speed) lo_speed = k;
      if (s.speed > in[hi_speed].speed) hi_speed = k;
      if (!busy && s.busy != in[i].busy) busy = k;
      if (!flag && s.flag != in[i].flag) flag = k;
      if (!sw && s.sw != in[i].sw) sw = k;
      if (!hiz && s.hiz != in[i].hiz) hiz = k;
      if (!mot && s.mot_status != in[i].mot_status) mot = k;
    }
    for (std::size_t k : {lo_pos, hi_pos, lo_speed, hi_speed, busy, flag, sw, hiz, mot})
      if (k) keep.push_back(k);
    std::sort(keep.begin(), keep.end());
    keep.erase(std::unique(keep.begin(), keep.end()), keep.end());
    for (std::size_t k : keep) out.push_back(in[k]);
    i = j;
  }
  return out;
}

/// Tells a PassProgress how far a reader has come: at the start, every kEventsPerReport
/// events and at the end (done == total), never going back.
class PassReporter {
 public:
  static constexpr std::uint32_t kEventsPerReport = 4096;
  PassReporter(const TraceReader& in, const PassProgress& progress) : in_(in), progress_(progress) { report(); }
  void event() {
    if (progress_ && ++count_ == kEventsPerReport) {
      count_ = 0;
      report();
    }
  }
  void end() {
    if (!progress_) return;
    ReadProgress p = in_.progress();
    p.done = std::max(p.done, done_);
    if (p.total == 0 || p.done > p.total) p.total = p.done;
    p.done = p.total;
    progress_(p);
  }

 private:
  void report() {
    if (!progress_) return;
    ReadProgress p = in_.progress();
    p.done = std::max(p.done, done_);  // a reader's count may stall; it never goes back here
    if (p.total != 0) p.done = std::min(p.done, p.total);
    done_ = p.done;
    progress_(p);
  }

  const TraceReader& in_;
  const PassProgress& progress_;
  std::uint32_t count_ = 0;
  std::uint64_t done_ = 0;
};

class Sampler {
 public:
  Sampler(Chain& chain, const MotionOptions& o, Tick from, Tick to, Tick step)
      : chain_(chain), from_(from), to_(to), step_(step), wanted_(chain.size(), -1) {
    const ChipNumbering numbering(o.number_from, chain.size());
    std::vector<std::size_t> chips = o.chips;
    if (chips.empty())
      for (std::size_t u = 0; u < chain.size(); ++u) chips.push_back(u);
    for (std::size_t u : chips) {
      if (u >= chain.size())
        throw std::invalid_argument("chip " + std::to_string(u) + ": the chain has " + counted(chain.size(), "chip") +
                                    " (0.." + std::to_string(chain.size() - 1) + "; " + numbering.description() + ")");
      const std::size_t k = numbering.index_of(u);
      if (wanted_[k] >= 0) continue;
      wanted_[k] = static_cast<int>(series_.size());
      ChipMotion m;
      m.chip = k;
      m.number = u;
      m.variant = std::string(chain.chip(k).variant().name);
      series_.push_back(std::move(m));
      rates_.push_back({!chain.chip(k).variant().has(Reg::SPEED)});
    }
    max_commands_ = o.max_commands;
    max_points_ = std::max<std::size_t>(o.max_points, 64);
  }

  bool wanted(std::size_t chip) const { return chip < wanted_.size() && wanted_[chip] >= 0; }
  bool in_window(Tick t) const { return t >= from_ && t <= to_; }

  void sample(std::size_t chip, Tick t) {
    if (!wanted(chip) || !in_window(t)) return;
    const auto index = static_cast<std::size_t>(wanted_[chip]);
    std::vector<MotionSample>& v = series_[index].samples;
    MotionSample s = sample_of(chain_.chip(chip), t);
    if (rates_[index].derived) s.speed = rates_[index].at(chain_.chip(chip), t, s.abs_pos, std::max(step_, kMinRateWindow));
    if (!v.empty() && v.back().tick == t)
      v.back() = s;  // the later state at the same tick wins
    else
      v.push_back(s);
    // Thinned as it grows, so a long trace never holds more than a few times max_points.
    if (v.size() > 8 * max_points_) v = thin(v, from_, to_, max_points_);
  }
  void sample_all(Tick t) {
    for (const ChipMotion& m : series_) sample(m.chip, t);
  }

  void command(std::size_t chip, Tick t, std::uint8_t opcode, std::uint32_t arg, const Variant& table,
               const StatusLayout& layout) {
    if (!wanted(chip) || !in_window(t)) return;
    ChipMotion& m = series_[static_cast<std::size_t>(wanted_[chip])];
    if (m.commands.size() >= max_commands_) {
      ++m.commands_dropped;
      return;
    }
    m.commands.push_back({t, opcode, opcode_name(opcode, table), describe_command(opcode, arg, table, layout)});
  }

  /// Moves the chain from its time up to `until`, sampling the wanted chips that move at every
  /// rule change, on the grid, and at the window's edges.
  void run_until(Tick until) {
    int boundaries = 0;  // boundary stops since the last grid tick
    std::vector<char> active(series_.size());
    while (chain_.now() < until) {
      const Tick now = chain_.now();
      Tick next = until;
      bool moving = false;
      for (std::size_t i = 0; i < series_.size(); ++i) {
        const Chip& c = chain_.chip(series_[i].chip);
        active[i] = motion_active(c.motion());
        if (!active[i]) continue;
        moving = true;
        // Before the window nothing is sampled: no need to stop at the rule changes there.
        if (now < from_ || boundaries >= kBoundariesPerGridStep) continue;
        const Tick u = uniform_ticks(c.motion(), c.profile(), until - now);
        if (u < until - now) next = std::min(next, now + u + 1);
      }
      if (now < from_) {
        next = std::min(next, from_);  // the window's first samples
      } else if (moving) {
        const Tick grid = from_ + ((now - from_) / step_ + 1) * step_;
        if (grid <= next) {
          next = grid;
          boundaries = 0;
        } else {
          ++boundaries;
        }
      }
      next = std::min(next, std::max(to_, now + 1));
      chain_.advance_to(next);
      if (next == from_ || next == to_) {
        sample_all(next);
        continue;
      }
      for (std::size_t i = 0; i < series_.size(); ++i)
        if (active[i] || motion_active(chain_.chip(series_[i].chip).motion())) sample(series_[i].chip, next);
    }
  }

  bool any_wanted_moving() const {
    for (const ChipMotion& m : series_)
      if (motion_active(chain_.chip(m.chip).motion())) return true;
    return false;
  }

  /// The series, thinned over the window as it ended up (`to`).
  std::vector<ChipMotion> finish(Tick to) {
    for (ChipMotion& m : series_) {
      const Chip& c = chain_.chip(m.chip);
      m.microsteps_per_step = 1u << c.profile().step_sel;
      m.samples = thin(m.samples, from_, to, max_points_);
    }
    return std::move(series_);
  }

 private:
  /// The step rate of a chip without a SPEED register, in SPEED's units: ABS_POS's change over
  /// the last window of at least `window` ticks, held until the next window closes.
  struct StepRate {
    bool derived = false;
    bool anchored = false;
    Tick anchor_tick = 0;
    std::int32_t anchor_pos = 0;
    std::int32_t rate = 0;

    std::int32_t at(const Chip& c, Tick t, std::int32_t pos, Tick window) {
      if (!anchored || t < anchor_tick) {
        anchored = true;
        anchor_tick = t;
        anchor_pos = pos;
        return rate = 0;
      }
      if (t - anchor_tick < window) return rate;
      // ABS_POS is 22 bits and wraps: the change is the short way round.
      const std::int32_t d = sign_extend(static_cast<std::uint32_t>(pos - anchor_pos), 22);
      const __int128 per_tick = static_cast<__int128>(d) * (std::int64_t{1} << 28) /
                                (static_cast<__int128>(t - anchor_tick) << c.profile().step_sel);
      rate = static_cast<std::int32_t>(std::clamp<__int128>(per_tick, INT32_MIN, INT32_MAX));
      anchor_tick = t;
      anchor_pos = pos;
      return rate;
    }
  };

  Chain& chain_;
  Tick from_, to_, step_;
  std::vector<int> wanted_;  // index into series_, -1 = not sampled
  std::vector<ChipMotion> series_;
  std::vector<StepRate> rates_;  // beside series_
  std::size_t max_commands_ = 0;
  std::size_t max_points_ = 64;
};

}  // namespace

Tick trace_end_tick(TraceReader& in, const PassProgress& progress) {
  PassReporter reporter(in, progress);
  Tick end = 0;
  TraceEvent e;
  while (in.next(e)) {
    end = std::max(end, e.kind == TraceEventKind::frame ? e.end() : e.tick);
    reporter.event();
  }
  reporter.end();
  return end;
}

MotionSeries sample_motion(TraceReader& in, Chain& chain, Tick trace_end, const MotionOptions& options) {
  if (options.max_points > kMaxMotionPoints)
    throw std::invalid_argument("max_points " + std::to_string(options.max_points) + ": at most " +
                                std::to_string(kMaxMotionPoints) + " samples per chip (a picture has a few thousand columns)");
  const Tick from = options.from;
  const Tick last = options.to != kNever ? options.to : trace_end + options.tail;
  if (from >= last) {
    if (options.to != kNever)
      throw std::invalid_argument("the window is empty: it ends before it begins");
    char when[48];
    std::snprintf(when, sizeof when, "t=%.6f s", static_cast<double>(trace_end) / kTicksPerSecond);
    throw std::invalid_argument(std::string("the window is empty: the trace ends at ") + when +
                                ", before the window begins");
  }
  const std::size_t max_points = std::max<std::size_t>(options.max_points, 64);
  // The grid: about max_points / 4 steps over the window (the trace's own part of it when open).
  const Tick grid_span = std::max<Tick>(1, (options.to != kNever ? last : std::max(trace_end, from + 1)) - from);
  const Tick step = std::max<Tick>(1, grid_span / (max_points / 4));

  Sampler sampler(chain, options, from, last, step);
  Tick frame_end = 0;
  std::vector<char> decoded(chain.size());  // chips that decoded a command that may change them, this frame
  ProtocolTracker tracker(chain, [&](const ProtocolEvent& p) {
    if (p.kind != ProtocolEvent::Kind::command || p.chip == ProtocolEvent::kNoChip) return;
    // GetStatus releases latched flags (FLAG may rise); GetParam and NOP change nothing.
    if (p.op.command == Command::GetStatus) decoded[p.chip] = 1;
    if (!listed_command(p.op.command)) return;
    decoded[p.chip] = 1;
    sampler.command(p.chip, frame_end, p.opcode, p.arg, *p.table, *p.layout);
  });

  if (chain.now() == from) sampler.sample_all(from);  // a window from the start: the power-up state
  PassReporter reporter(in, options.progress);
  DivergenceWatch watch(in.header().name, ChipNumbering(options.number_from, chain.size()));
  std::vector<std::uint8_t> rx;
  TraceEvent e;
  bool ended = true;
  while (in.next(e)) {
    reporter.event();
    const Tick at = e.kind == TraceEventKind::frame ? e.end() : e.tick;
    if (at > last) {
      ended = false;
      break;
    }
    if (e.kind != TraceEventKind::frame && e.chip >= chain.size())
      throw TraceError(in.header().name, e.line,
                       trace_chip_outside_chain(e.chip, chain.size()));
    // Up to the moment the event acts (a frame's CS rising edge, when the chips decode).
    sampler.run_until(at);
    if (e.kind == TraceEventKind::frame) {
      frame_end = at;
      rx.resize(e.mosi.size());
      tracker.begin_frame(e, rx);
      watch.frame(e, rx);
      tracker.end_frame();
      for (std::size_t k = 0; k < chain.size(); ++k)
        if (decoded[k]) {
          sampler.sample(k, at);
          decoded[k] = 0;
        }
    } else {
      tracker.apply(e);
      // Pin observations (BUSY, FLAG) change nothing, but are checked; inputs, faults and loads may.
      if (e.is_observation()) {
        const Chip& chip = chain.chip(e.chip);
        watch.observation(e, observed_level(chip, e.pin));
      } else if (e.kind != TraceEventKind::advance) {
        sampler.sample(e.chip, at);
      }
    }
  }
  if (ended) tracker.finish();
  Tick to = last;
  if (options.to == kNever) {
    // After the trace: follow motion still going for at most `tail`, then stop where it ends.
    const Tick tail_end = last;
    to = std::max(trace_end, from + 1);
    if (chain.now() < to) sampler.run_until(to);
    while (sampler.any_wanted_moving() && chain.now() < tail_end) {
      sampler.run_until(std::min(tail_end, chain.now() + step));
      to = chain.now();
    }
  } else if (chain.now() < to) {
    sampler.run_until(to);
  }
  MotionSeries out;
  out.from = from;
  out.to = to;
  out.trace_end = trace_end;
  // The last samples close the window (the sampler only looks at moving chips).
  sampler.sample_all(std::min(chain.now(), to));
  out.chips = sampler.finish(to);
  out.divergence = watch.first();
  out.frames_diverged = watch.frames_diverged();
  out.pins_diverged = watch.pins_diverged();
  reporter.end();
  return out;
}

}  // namespace l6470emu
