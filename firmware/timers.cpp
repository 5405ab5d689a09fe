// FirmwareTimers: counters, periods and compares in virtual time; their output as a board pulse
// train, their update and compare events as interrupts pended at the exact tick (the runtime's
// side, time passing event by event, is in runtime.cpp's timers section).
#include "firmware/timers.hpp"

#include <algorithm>

#include "firmware/runtime.hpp"

namespace l6470emu {

// ---------------------------------------------------------------- timers

int FirmwareTimers::add(std::string name) {
  Timer t;
  t.name = std::move(name);
  timers_.push_back(std::move(t));
  return static_cast<int>(timers_.size() - 1);
}

int FirmwareTimers::find(const std::string& name) const {
  for (std::size_t i = 0; i < timers_.size(); ++i)
    if (timers_[i].name == name) return static_cast<int>(i);
  return -1;
}

FirmwareTimers::Timer& FirmwareTimers::at(int timer) { return timers_.at(static_cast<std::size_t>(timer)); }
const FirmwareTimers::Timer& FirmwareTimers::at(int timer) const { return timers_.at(static_cast<std::size_t>(timer)); }

void FirmwareTimers::set_clock(int timer, std::uint64_t hz) {
  Timer& t = at(timer);
  if (hz == 0) return rt_.log(t.name + ": a timer clock of 0 Hz is ignored");
  const bool was = t.running;
  if (was) stop(timer);
  t.clock_hz = hz;
  if (was) start(timer);
}
std::uint64_t FirmwareTimers::clock(int timer) const { return at(timer).clock_hz; }

void FirmwareTimers::set_prescaler(int timer, std::uint32_t division) {
  Timer& t = at(timer);
  t.next_prescaler = std::max<std::uint32_t>(division, 1);  // always buffered, as PSC is
  if (!t.running) t.prescaler = t.next_prescaler;
}
std::uint32_t FirmwareTimers::prescaler(int timer) const { return at(timer).next_prescaler; }

void FirmwareTimers::set_preload(int timer, bool on) { at(timer).preload = on; }
bool FirmwareTimers::preload(int timer) const { return at(timer).preload; }

void FirmwareTimers::set_period(int timer, std::uint64_t counts) {
  Timer& t = at(timer);
  t.next_period = std::max<std::uint64_t>(counts, 1);
  if (!t.running) t.period = t.next_period;
  if (t.running && !t.preload) apply_now(t);
}
std::uint64_t FirmwareTimers::period(int timer) const { return at(timer).next_period; }

void FirmwareTimers::apply_now(Timer& t) {
  if (t.next_period == t.period && t.next_compare == t.compare) return;
  const std::uint64_t count = counter(static_cast<int>(&t - timers_.data()));
  if (count >= t.next_period) return;  // the counter is past it already: from the next update on
  // The period under way restarts its origin at its own start, with the new values.
  t.origin = tick_at(t, t.updates * t.period);
  t.updates = 0;
  t.compares = t.next_compare > 0 && count >= t.next_compare ? 1 : 0;  // a match already passed
  t.period = t.next_period;
  t.compare = t.next_compare;
  drive_output(t, true);
}

void FirmwareTimers::set_compare(int timer, std::uint64_t counts) {
  Timer& t = at(timer);
  t.next_compare = counts;
  if (!t.running) t.compare = counts;
  if (t.running && !t.preload) apply_now(t);
}
std::uint64_t FirmwareTimers::compare(int timer) const { return at(timer).next_compare; }

void FirmwareTimers::set_output(int timer, int key) {
  Timer& t = at(timer);
  if (key == t.output) return;
  if (t.running) drive_output(t, false);
  t.output = key;
  if (t.running) drive_output(t, true);
}
int FirmwareTimers::output(int timer) const { return at(timer).output; }

void FirmwareTimers::set_pulse_count(int timer, std::uint64_t pulses) { at(timer).pulse_count = pulses; }
void FirmwareTimers::set_update_irq(int timer, int irq) { at(timer).update_irq = irq; }
void FirmwareTimers::set_compare_irq(int timer, int irq) { at(timer).compare_irq = irq; }
bool FirmwareTimers::running(int timer) const { return at(timer).running; }

void FirmwareTimers::start(int timer) {
  Timer& t = at(timer);
  if (t.running) return;
  t.running = true;
  t.prescaler = t.next_prescaler;
  t.period = t.next_period;
  t.compare = t.next_compare;
  t.origin = rt_.now();
  t.updates = t.compares = 0;
  drive_output(t, true);
}

void FirmwareTimers::stop(int timer) {
  Timer& t = at(timer);
  if (!t.running) return;
  drive_output(t, false);
  t.running = false;
  t.prescaler = t.next_prescaler;
  t.period = t.next_period;
  t.compare = t.next_compare;
}

Tick FirmwareTimers::tick_at(const Timer& t, std::uint64_t counts) {
  return t.origin + static_cast<Tick>(static_cast<unsigned __int128>(counts) * t.prescaler * kTicksPerSecond / t.clock_hz);
}

std::uint64_t FirmwareTimers::counter(int timer) const {
  const Timer& t = at(timer);
  if (!t.running) return 0;
  // Input-clock counts since the origin, floor((now - origin) × clock / TPS), then the counter.
  const auto elapsed = static_cast<unsigned __int128>(rt_.now() - t.origin) * t.clock_hz / kTicksPerSecond;
  return static_cast<std::uint64_t>(elapsed / t.prescaler % t.period);
}

void FirmwareTimers::set_counter(int timer, std::uint64_t value) {
  Timer& t = at(timer);
  if (!t.running) return;
  // A new origin `value` counts in the past (or the present, when the time is too short for it).
  const auto back = static_cast<Tick>(static_cast<unsigned __int128>(value % t.period) * t.prescaler * kTicksPerSecond /
                                      t.clock_hz);
  drive_output(t, false);
  t.origin = rt_.now() - std::min<Tick>(back, rt_.now());
  t.updates = t.compares = 0;
  drive_output(t, true);
}

Tick FirmwareTimers::next_update(const Timer& t) const {
  if (!t.running || (t.update_irq < 0 && !t.pending_change())) return kNever;
  return tick_at(t, (t.updates + 1) * t.period);
}

Tick FirmwareTimers::next_compare(const Timer& t) const {
  if (!t.running || t.compare_irq < 0 || t.compare == 0 || t.compare >= t.period) return kNever;
  return tick_at(t, t.compares * t.period + t.compare);
}

Tick FirmwareTimers::next_event() const {
  Tick best = kNever;
  for (const Timer& t : timers_) best = std::min({best, next_update(t), next_compare(t)});
  return best;
}

void FirmwareTimers::fire_through(Tick now) {
  for (Timer& t : timers_) {
    for (;;) {
      const Tick u = next_update(t), c = next_compare(t);
      if (std::min(u, c) > now) break;
      if (c < u) {
        ++t.compares;
        rt_.pend_irq(t.compare_irq);
        continue;
      }
      ++t.updates;
      if (t.pending_change()) {
        // The preloaded period and compare take effect: the counter restarts from this update.
        t.origin = u;
        t.updates = t.compares = 0;
        t.prescaler = t.next_prescaler;
        t.period = t.next_period;
        t.compare = t.next_compare;
        drive_output(t, true);
      }
      if (t.update_irq >= 0) rt_.pend_irq(t.update_irq);
    }
  }
}

void FirmwareTimers::drive_output(Timer& t, bool on) {
  if (t.output < 0) return;
  if (!on) {
    rt_.drive_pulse_train(t.output, nullptr);
    return;
  }
  if (t.compare == 0) {  // PWM mode 1 with CCR 0: low throughout
    rt_.drive_pulse_train(t.output, nullptr);
    return;
  }
  PulseTrain train;
  train.start = t.origin;
  train.clock_hz = t.clock_hz;
  train.period_counts = t.period * t.prescaler;
  // CCR at or above the period: high throughout, one pulse as long as the timer runs.
  train.high_counts = t.compare >= t.period ? train.period_counts : t.compare * t.prescaler;
  if (train.high_counts >= train.period_counts) {
    train.period_counts = ~std::uint64_t{0} / 2;
    train.high_counts = train.period_counts - 1;
  }
  // An output enabled while the counter runs makes its first pulse at the next counter reset.
  if (rt_.now() > t.origin) train.first = train.rises_through(rt_.now() - 1);
  train.count = t.pulse_count;  // tone's duration: so many pulses from the start
  rt_.drive_pulse_train(t.output, &train);
}

}  // namespace l6470emu
