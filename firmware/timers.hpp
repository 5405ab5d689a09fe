// The microcontroller's timers in virtual time: an up-counting counter with a prescaler, an
// auto-reload (the period) and one PWM compare, whose output pin drives the board as a pulse
// train and whose update and compare events pend interrupts at their exact ticks. What the
// Arduino (tone, analogWrite, STM32duino's HardwareTimer) and STM32 HAL (TIM) fronts stand on.
// Not modelled: down and centre-aligned counting, input capture, one-pulse mode, dead time,
// several channels of one timer driving different pins at different duties (one compare each).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/tick.hpp"

namespace l6470emu {

class FirmwareRuntime;

/// The timers of a firmware run, numbered from 0 as add() makes them. A timer counts at
/// clock_hz / prescaler; a period is `period` counts (ARR + 1), the PWM output (mode 1) is high
/// while the counter is below `compare` (CCR): pulses rise at every counter reset and fall at
/// the compare match, so the output pin sees one pulse per period unless compare is 0 (low) or
/// at least the period (high). With the preload on (ARPE, OCxPE: STM32duino's default, the HAL's
/// AutoReloadPreload) a change of period or compare while the timer runs takes effect at its
/// next update event; with it off, at once for the period under way (when the counter has
/// not passed the new value yet; else at the next update). A stopped timer takes it at once.
class FirmwareTimers {
 public:
  explicit FirmwareTimers(FirmwareRuntime& runtime) : rt_(runtime) {}

  /// A new timer called `name` (for diagnostics), stopped: 4 MHz clock, prescaler 1, period
  /// 65536 counts, compare 0, no output, no interrupts. Returns its number.
  int add(std::string name);
  /// The timer called `name`, or -1.
  int find(const std::string& name) const;
  /// The counter's input clock, Hz (> 0); a running timer restarts from 0 on a new one.
  void set_clock(int timer, std::uint64_t hz);
  std::uint64_t clock(int timer) const;
  /// The prescaler's division (PSC + 1, >= 1): always buffered, in force from the next update
  /// (at once while stopped).
  void set_prescaler(int timer, std::uint32_t division);
  std::uint32_t prescaler(int timer) const;
  /// Counts per period (ARR + 1, >= 1).
  void set_period(int timer, std::uint64_t counts);
  std::uint64_t period(int timer) const;
  /// The compare value (CCR), counts: the PWM output is high while the counter is below it.
  void set_compare(int timer, std::uint64_t counts);
  std::uint64_t compare(int timer) const;
  /// Whether a new period or compare waits for the next update (true, the default).
  void set_preload(int timer, bool on);
  bool preload(int timer) const;
  /// The pin (a runtime pin key) the PWM output drives; -1: none. Takes effect at once.
  void set_output(int timer, int key);
  int output(int timer) const;
  /// How many pulses the output makes before it stays low (Arduino's tone with a duration);
  /// 0 = until stopped. Counted from the next start.
  void set_pulse_count(int timer, std::uint64_t pulses);
  /// Interrupts (FirmwareRuntime::add_irq numbers) pended at each update event (counter
  /// overflow) and each compare match; -1: none. While either is set the timer's events are
  /// met one by one; with neither, a running timer costs nothing per pulse.
  void set_update_irq(int timer, int irq);
  void set_compare_irq(int timer, int irq);
  /// Starts the counter from 0 now (the output's first pulse rises now).
  void start(int timer);
  /// Stops the counter now; the output goes low.
  void stop(int timer);
  bool running(int timer) const;
  /// The counter now (0 when stopped).
  std::uint64_t counter(int timer) const;
  /// Sets the counter now (a running timer's period restarts from `value`'s phase at once).
  void set_counter(int timer, std::uint64_t value);

  /// The earliest tick at which a timer event is due (kNever: none): the runtime wakes for it.
  Tick next_event() const;
  /// Handles every event due at or before `now` (the runtime's time): interrupts pended,
  /// pending periods and compares taken at updates.
  void fire_through(Tick now);

 private:
  struct Timer {
    std::string name;
    std::uint64_t clock_hz = 4'000'000;
    std::uint32_t prescaler = 1, next_prescaler = 1;  // in force; from the next update on
    std::uint64_t period = 65536, compare = 0;                // in force
    std::uint64_t next_period = 65536, next_compare = 0;      // from the next update on
    int output = -1;
    std::uint64_t pulse_count = 0;
    int update_irq = -1, compare_irq = -1;
    bool running = false;
    bool preload = true;
    Tick origin = 0;              // the tick the counter was last 0 from a start or an update taking a change
    std::uint64_t updates = 0;    // update events since origin already handled
    std::uint64_t compares = 0;   // compare matches since origin already handled
    bool pending_change() const {
      return next_period != period || next_compare != compare || next_prescaler != prescaler;
    }
  };
  Timer& at(int timer);
  const Timer& at(int timer) const;
  /// The tick `counts` input-clock counts after the origin.
  static Tick tick_at(const Timer& t, std::uint64_t counts);
  Tick next_update(const Timer& t) const;
  Tick next_compare(const Timer& t) const;
  /// Puts the output's pulse train on the board from the origin (or takes it off).
  void drive_output(Timer& t, bool on);
  /// Without the preload: the period and compare just written, for the period under way.
  void apply_now(Timer& t);

  FirmwareRuntime& rt_;
  std::vector<Timer> timers_;
};

}  // namespace l6470emu
