// STM32duino's HardwareTimer and pin map calls over the runtime's timers (firmware/timers.hpp):
// formats turned into prescaler, overflow and compare as STM32duino computes them, the channel
// with a pin as the timer's output, callbacks as runtime interrupts. Each call is one HAL call.
// The model first: Arduino.h's macros (HIGH, DEC, ...) must not reach its headers.
#include "firmware/arduino/arduino_internal.hpp"
#include "firmware/timer_pins.hpp"

#include <string>

#include "Arduino.h"
#include "HardwareTimer.h"

using l6470emu::FirmwareRuntime;
using l6470emu::FirmwareTimers;
using l6470emu::arduino::runtime;

extern "C" {

TIM_TypeDef l6470emu_tim[18] = {{0}, {1}, {2}, {3}, {4}, {5}, {6}, {7}, {8}, {9}, {10}, {11}, {12}, {13}, {14}, {15}, {16}, {17}};

#define L6470EMU_PWM_ROW(port, pin, timer, channel, af, inverted)                                        \
  PinMap{static_cast<PinName>(port##_0 + pin), &l6470emu_tim[timer],                                     \
         static_cast<int>((channel) << STM_PIN_CHANNEL_SHIFT | (af) << STM_PIN_AFNUM_SHIFT | (inverted) << STM_PIN_INV_SHIFT)},
const PinMap PinMap_PWM[] = {L6470EMU_F401_TIMER_PINS(L6470EMU_PWM_ROW) PinMap{NC, nullptr, 0}};
#undef L6470EMU_PWM_ROW

PinName digitalPinToPinName(uint32_t pin) {
  const int key = runtime().arduino_pin(static_cast<int>(pin));
  return key >= 128 && key < 256 ? static_cast<PinName>(key - 128) : NC;
}

void* pinmap_peripheral(PinName pin, const PinMap* map) {
  for (; map && map->pin != NC; ++map)
    if (map->pin == pin) return map->peripheral;
  return nullptr;
}

uint32_t pinmap_function(PinName pin, const PinMap* map) {
  for (; map && map->pin != NC; ++map)
    if (map->pin == pin) return static_cast<uint32_t>(map->function);
  return static_cast<uint32_t>(NC);
}

}  // extern "C"

namespace {

constexpr uint64_t kClockHz = l6470emu::kF401TimerClockHz;

/// One HAL call's cost, then the runtime.
FirmwareRuntime& call() {
  FirmwareRuntime& r = runtime();
  r.call();
  return r;
}

bool outputs(TimerModes_t m) {
  return m == TIMER_OUTPUT_COMPARE_PWM1 || m == TIMER_OUTPUT_COMPARE_PWM2 || m == TIMER_OUTPUT_COMPARE_FORCED_ACTIVE ||
         m == TIMER_OUTPUT_COMPARE_FORCED_INACTIVE;
}

bool valid_channel(uint32_t channel) { return channel >= 1 && channel <= TIMER_CHANNELS; }

}  // namespace

HardwareTimer::HardwareTimer() = default;

HardwareTimer::HardwareTimer(TIM_TypeDef* instance) { setup(instance); }

HardwareTimer::~HardwareTimer() {
  if (timer_ < 0) return;
  FirmwareRuntime& r = runtime();
  r.timers().stop(timer_);
  r.timers().set_update_irq(timer_, -1);
  r.timers().set_compare_irq(timer_, -1);
  r.clear_irq(update_irq_);
  r.clear_irq(compare_irq_);
}

void HardwareTimer::setup(TIM_TypeDef* instance) {
  FirmwareRuntime& r = call();
  if (!instance || instance < &l6470emu_tim[1] || instance > &l6470emu_tim[17]) {
    r.log("HardwareTimer: an instance that is none of TIM1 to TIM17: the timer does nothing");
    return;
  }
  number_ = instance->l6470emu_number;
  const std::string name = "TIM" + std::to_string(number_);
  FirmwareTimers& t = r.timers();
  timer_ = t.find(name) >= 0 ? t.find(name) : t.add(name);
  t.set_clock(timer_, kClockHz);
  t.set_prescaler(timer_, prescale_);
  t.set_period(timer_, overflow_);
  update_irq_ = r.add_irq([this] {
    if (callbacks_[0]) callbacks_[0]();
  });
  compare_irq_ = r.add_irq([this] {
    if (compare_channel_ >= 0 && callbacks_[compare_channel_ + 1]) callbacks_[compare_channel_ + 1]();
  });
}

void HardwareTimer::apply_channels() {
  if (timer_ < 0) return;
  FirmwareRuntime& r = runtime();
  FirmwareTimers& t = r.timers();
  // The output: the last enabled channel in an output mode with a pin.
  int out = -1;
  for (int c = 0; c < TIMER_CHANNELS; ++c)
    if (channel_on_[c] && outputs(mode_[c]) && pin_[c] != NC) out = c;
  compare_channel_ = out;
  if (compare_channel_ < 0)
    for (int c = 0; c < TIMER_CHANNELS && compare_channel_ < 0; ++c)
      if (channel_on_[c] && callbacks_[c + 1]) compare_channel_ = c;
  uint64_t compare = 0;
  if (compare_channel_ >= 0) {
    const auto c = static_cast<std::size_t>(compare_channel_);
    switch (mode_[c]) {
      case TIMER_OUTPUT_COMPARE_PWM2: compare = compare_[c] >= overflow_ ? 0 : overflow_ - compare_[c]; break;  // its high time
      case TIMER_OUTPUT_COMPARE_FORCED_ACTIVE: compare = overflow_; break;
      case TIMER_OUTPUT_COMPARE_FORCED_INACTIVE: compare = 0; break;
      default: compare = compare_[c]; break;
    }
  }
  t.set_compare(timer_, compare);
  t.set_output(timer_, out >= 0 ? 128 + static_cast<int>(pin_[out]) : -1);
  t.set_update_irq(timer_, callbacks_[0] ? update_irq_ : -1);
  t.set_compare_irq(timer_, compare_channel_ >= 0 && callbacks_[compare_channel_ + 1] ? compare_irq_ : -1);
}

void HardwareTimer::pause(void) {
  call();
  if (timer_ >= 0) runtime().timers().stop(timer_);
}

void HardwareTimer::pauseChannel(uint32_t channel) {
  call();
  if (!valid_channel(channel)) return;
  channel_on_[channel - 1] = false;
  apply_channels();
}

void HardwareTimer::resume(void) {
  call();
  if (timer_ < 0) return;
  for (int c = 0; c < TIMER_CHANNELS; ++c)
    if (mode_[c] != TIMER_NOT_USED) channel_on_[c] = true;
  apply_channels();
  runtime().timers().start(timer_);
}

void HardwareTimer::resumeChannel(uint32_t channel) {
  call();
  if (!valid_channel(channel)) return;
  channel_on_[channel - 1] = true;
  apply_channels();
}

void HardwareTimer::setPrescaleFactor(uint32_t prescaler) {
  call();
  prescale_ = prescaler == 0 ? 1 : (prescaler > 65536 ? 65536 : prescaler);
  if (timer_ >= 0) runtime().timers().set_prescaler(timer_, prescale_);
}

uint32_t HardwareTimer::getPrescaleFactor() {
  call();
  return prescale_;
}

void HardwareTimer::setOverflow(uint32_t val, TimerFormat_t format) {
  FirmwareRuntime& r = call();
  uint64_t cycles = 0;
  switch (format) {
    case MICROSEC_FORMAT: cycles = static_cast<uint64_t>(val) * (kClockHz / 1'000'000); break;
    case HERTZ_FORMAT:
      if (val == 0) return r.log("HardwareTimer::setOverflow: 0 Hz is no period: ignored");
      cycles = kClockHz / val;
      break;
    default: overflow_ = val == 0 ? 1 : val; break;
  }
  if (format == MICROSEC_FORMAT || format == HERTZ_FORMAT) {
    // STM32duino's choice: the smallest prescaler that leaves the period within 16 bits.
    prescale_ = static_cast<uint32_t>(cycles / 0x10000 + 1);
    overflow_ = static_cast<uint32_t>(cycles / prescale_);
    if (overflow_ == 0) overflow_ = 1;
    if (timer_ >= 0) r.timers().set_prescaler(timer_, prescale_);
  }
  if (timer_ >= 0) r.timers().set_period(timer_, overflow_);
}

uint32_t HardwareTimer::getOverflow(TimerFormat_t format) {
  call();
  const uint64_t cycles = static_cast<uint64_t>(overflow_) * prescale_;
  switch (format) {
    case MICROSEC_FORMAT: return static_cast<uint32_t>(cycles / (kClockHz / 1'000'000));
    case HERTZ_FORMAT: return static_cast<uint32_t>(kClockHz / cycles);
    default: return overflow_;
  }
}

void HardwareTimer::setPWM(uint32_t channel, PinName pin, uint32_t frequency, uint32_t dutycycle,
                           callback_function_t PeriodCallback, callback_function_t CompareCallback) {
  setMode(channel, TIMER_OUTPUT_COMPARE_PWM1, pin);
  setOverflow(frequency, HERTZ_FORMAT);
  setCaptureCompare(channel, dutycycle, PERCENT_COMPARE_FORMAT);
  if (PeriodCallback) attachInterrupt(PeriodCallback);
  if (CompareCallback) attachInterrupt(channel, CompareCallback);
  resume();
}

void HardwareTimer::setPWM(uint32_t channel, uint32_t pin, uint32_t frequency, uint32_t dutycycle,
                           callback_function_t PeriodCallback, callback_function_t CompareCallback) {
  setPWM(channel, digitalPinToPinName(pin), frequency, dutycycle, std::move(PeriodCallback), std::move(CompareCallback));
}

void HardwareTimer::setCount(uint32_t val, TimerFormat_t format) {
  call();
  if (timer_ < 0) return;
  uint64_t ticks = val;
  if (format == MICROSEC_FORMAT) ticks = static_cast<uint64_t>(val) * (kClockHz / 1'000'000) / prescale_;
  if (format == HERTZ_FORMAT) ticks = val ? kClockHz / (static_cast<uint64_t>(val) * prescale_) : 0;
  runtime().timers().set_counter(timer_, ticks);
}

uint32_t HardwareTimer::getCount(TimerFormat_t format) {
  call();
  if (timer_ < 0) return 0;
  const uint64_t ticks = runtime().timers().counter(timer_);
  if (format == MICROSEC_FORMAT) return static_cast<uint32_t>(ticks * prescale_ / (kClockHz / 1'000'000));
  if (format == HERTZ_FORMAT) return ticks ? static_cast<uint32_t>(kClockHz / (ticks * prescale_)) : 0;
  return static_cast<uint32_t>(ticks);
}

void HardwareTimer::setMode(uint32_t channel, TimerModes_t mode, PinName pin, ChannelInputFilter_t) {
  FirmwareRuntime& r = call();
  if (!valid_channel(channel)) return r.log("HardwareTimer::setMode: channel " + std::to_string(channel) + " is none of 1 to 4");
  if (mode >= TIMER_INPUT_CAPTURE_RISING && mode != TIMER_NOT_USED)
    r.log("HardwareTimer: input capture is not modelled (TIM" + std::to_string(number_) + " channel " +
          std::to_string(channel) + ")");
  if (mode == TIMER_OUTPUT_COMPARE_ACTIVE || mode == TIMER_OUTPUT_COMPARE_INACTIVE || mode == TIMER_OUTPUT_COMPARE_TOGGLE)
    r.log("HardwareTimer: output compare modes other than PWM drive no pin here (TIM" + std::to_string(number_) + ")");
  mode_[channel - 1] = mode;
  pin_[channel - 1] = pin;
  apply_channels();
}

void HardwareTimer::setMode(uint32_t channel, TimerModes_t mode, uint32_t pin, ChannelInputFilter_t filter) {
  setMode(channel, mode, digitalPinToPinName(pin), filter);
}

TimerModes_t HardwareTimer::getMode(uint32_t channel) {
  call();
  return valid_channel(channel) ? mode_[channel - 1] : TIMER_NOT_USED;
}

void HardwareTimer::setPreloadEnable(bool value) {
  call();
  if (timer_ >= 0) runtime().timers().set_preload(timer_, value);
}

uint32_t HardwareTimer::getCaptureCompare(uint32_t channel, TimerCompareFormat_t format) {
  call();
  if (!valid_channel(channel)) return 0;
  const uint64_t ccr = compare_[channel - 1];
  if (format == PERCENT_COMPARE_FORMAT) return static_cast<uint32_t>(ccr * 100 / overflow_);
  if (format >= RESOLUTION_1B_COMPARE_FORMAT && format <= RESOLUTION_16B_COMPARE_FORMAT)
    return static_cast<uint32_t>(ccr * ((1u << format) - 1) / overflow_);
  if (format == MICROSEC_COMPARE_FORMAT) return static_cast<uint32_t>(ccr * prescale_ / (kClockHz / 1'000'000));
  if (format == HERTZ_COMPARE_FORMAT) return ccr ? static_cast<uint32_t>(kClockHz / (ccr * prescale_)) : 0;
  return static_cast<uint32_t>(ccr);
}

void HardwareTimer::setCaptureCompare(uint32_t channel, uint32_t compare, TimerCompareFormat_t format) {
  FirmwareRuntime& r = call();
  if (!valid_channel(channel))
    return r.log("HardwareTimer::setCaptureCompare: channel " + std::to_string(channel) + " is none of 1 to 4");
  uint64_t ccr = compare;
  if (format == PERCENT_COMPARE_FORMAT) ccr = static_cast<uint64_t>(overflow_) * compare / 100;
  if (format >= RESOLUTION_1B_COMPARE_FORMAT && format <= RESOLUTION_16B_COMPARE_FORMAT) {
    const uint64_t full = (1u << format) - 1;
    ccr = compare >= full ? overflow_ : static_cast<uint64_t>(overflow_) * compare / full;
  }
  if (format == MICROSEC_COMPARE_FORMAT) ccr = static_cast<uint64_t>(compare) * (kClockHz / 1'000'000) / prescale_;
  if (format == HERTZ_COMPARE_FORMAT) ccr = compare ? kClockHz / (static_cast<uint64_t>(compare) * prescale_) : 0;
  compare_[channel - 1] = static_cast<uint32_t>(ccr);
  apply_channels();
}

void HardwareTimer::setInterruptPriority(uint32_t, uint32_t) { call(); }

void HardwareTimer::attachInterrupt(callback_function_t callback) {
  call();
  callbacks_[0] = std::move(callback);
  apply_channels();
}

void HardwareTimer::detachInterrupt() {
  call();
  callbacks_[0] = nullptr;
  apply_channels();
}

bool HardwareTimer::hasInterrupt() { return static_cast<bool>(callbacks_[0]); }

void HardwareTimer::attachInterrupt(uint32_t channel, callback_function_t callback) {
  FirmwareRuntime& r = call();
  if (!valid_channel(channel))
    return r.log("HardwareTimer::attachInterrupt: channel " + std::to_string(channel) + " is none of 1 to 4");
  callbacks_[channel] = std::move(callback);
  if (mode_[channel - 1] == TIMER_NOT_USED) mode_[channel - 1] = TIMER_OUTPUT_DISABLED;
  apply_channels();
}

void HardwareTimer::detachInterrupt(uint32_t channel) {
  call();
  if (!valid_channel(channel)) return;
  callbacks_[channel] = nullptr;
  apply_channels();
}

bool HardwareTimer::hasInterrupt(uint32_t channel) { return valid_channel(channel) && callbacks_[channel]; }

void HardwareTimer::timerHandleDeinit() {
  pause();
  for (auto& cb : callbacks_) cb = nullptr;
  apply_channels();
}

void HardwareTimer::refresh(void) {
  call();
  if (timer_ < 0) return;
  FirmwareTimers& t = runtime().timers();
  // An update event generated by software: the preloaded values in force, the counter from 0.
  if (t.running(timer_)) {
    t.stop(timer_);
    t.start(timer_);
  }
}

uint32_t HardwareTimer::getTimerClkFreq() {
  call();
  return static_cast<uint32_t>(kClockHz);
}

bool HardwareTimer::isRunning() { return timer_ >= 0 && runtime().timers().running(timer_); }

bool HardwareTimer::isRunningChannel(uint32_t channel) {
  return isRunning() && valid_channel(channel) && channel_on_[channel - 1];
}
