/* STM32duino's HardwareTimer (and the pin map calls that find a pin's timer) over l6470emu's
 * virtual-time timers (docs/firmware.md, "Timers"): a PWM channel on a pin wired to STCK drives
 * it as a pulse train, update and compare callbacks run at their exact virtual ticks. The timers
 * are a NUCLEO-F401RE's (84 MHz input clock, the F401's pin table). Not modelled: input capture,
 * output compare modes other than PWM1/PWM2/forced, several output channels of one timer at once
 * (the last channel given a pin drives it), interrupt priorities. No registers: a TIM_TypeDef is
 * a name. */
#ifndef L6470EMU_HARDWARE_TIMER_H
#define L6470EMU_HARDWARE_TIMER_H

#include <stdint.h>

#ifdef __cplusplus
#include <functional>
#endif

/* A timer instance: TIM1 ... TIM17 are distinct addresses; nothing is behind them. */
typedef struct TIM_TypeDef {
  uint32_t l6470emu_number; /* the x of TIMx */
} TIM_TypeDef;

#ifdef __cplusplus
extern "C" {
#endif
extern TIM_TypeDef l6470emu_tim[18];
#ifdef __cplusplus
}
#endif
#define TIM1 (&l6470emu_tim[1])
#define TIM2 (&l6470emu_tim[2])
#define TIM3 (&l6470emu_tim[3])
#define TIM4 (&l6470emu_tim[4])
#define TIM5 (&l6470emu_tim[5])
#define TIM6 (&l6470emu_tim[6])
#define TIM7 (&l6470emu_tim[7])
#define TIM8 (&l6470emu_tim[8])
#define TIM9 (&l6470emu_tim[9])
#define TIM10 (&l6470emu_tim[10])
#define TIM11 (&l6470emu_tim[11])
#define TIM12 (&l6470emu_tim[12])
#define TIM13 (&l6470emu_tim[13])
#define TIM14 (&l6470emu_tim[14])
#define TIM15 (&l6470emu_tim[15])
#define TIM16 (&l6470emu_tim[16])
#define TIM17 (&l6470emu_tim[17])

/* STM32duino's pin names: port × 16 + pin (PA_0 = 0x00, PC_7 = 0x27); NC: not connected. */
typedef enum {
#define L6470EMU_PORT_PINS(P, base)                                                                              \
  P##_0 = base, P##_1, P##_2, P##_3, P##_4, P##_5, P##_6, P##_7, P##_8, P##_9, P##_10, P##_11, P##_12, P##_13, \
  P##_14, P##_15
  L6470EMU_PORT_PINS(PA, 0x00), L6470EMU_PORT_PINS(PB, 0x10), L6470EMU_PORT_PINS(PC, 0x20),
  L6470EMU_PORT_PINS(PD, 0x30), L6470EMU_PORT_PINS(PE, 0x40), L6470EMU_PORT_PINS(PF, 0x50),
  L6470EMU_PORT_PINS(PG, 0x60), L6470EMU_PORT_PINS(PH, 0x70),
#undef L6470EMU_PORT_PINS
  NC = (int)0xFFFFFFFF
} PinName;

/* A pin map row (STM32duino's PinMap): the pin, its peripheral, the function word (channel inside). */
typedef struct {
  PinName pin;
  void* peripheral;
  int function;
} PinMap;

/* The F401's PWM outputs (firmware/timer_pins.cpp), ending with an NC row. */
#ifdef __cplusplus
extern "C" {
#endif
extern const PinMap PinMap_PWM[];
/* The port pin behind an Arduino pin number (NC when it has none: an Uno's pins). */
PinName digitalPinToPinName(uint32_t pin);
/* The peripheral (a TIM_TypeDef*) the map gives `pin`, or NULL. */
void* pinmap_peripheral(PinName pin, const PinMap* map);
/* The function word the map gives `pin` (STM_PIN_CHANNEL reads its channel), or NC. */
uint32_t pinmap_function(PinName pin, const PinMap* map);
#ifdef __cplusplus
}
#endif

/* The function word's fields, as STM32duino packs them (channel in bits 15-19, inverted: CHxN). */
#define STM_PIN_CHANNEL_SHIFT 15
#define STM_PIN_CHANNEL_MASK 0x1F
#define STM_PIN_INV_SHIFT 20
#define STM_PIN_AFNUM_SHIFT 7
#define STM_PIN_AFNUM_MASK 0x7F
#define STM_PIN_CHANNEL(X) (((X) >> STM_PIN_CHANNEL_SHIFT) & STM_PIN_CHANNEL_MASK)
#define STM_PIN_INVERTED(X) (((X) >> STM_PIN_INV_SHIFT) & 0x01)
#define STM_PIN_AFNUM(X) (((X) >> STM_PIN_AFNUM_SHIFT) & STM_PIN_AFNUM_MASK)

#ifdef __cplusplus

#define TIMER_CHANNELS 4

/* Channel modes (STM32duino's names). */
typedef enum {
  TIMER_OUTPUT_DISABLED,
  TIMER_OUTPUT_COMPARE_ACTIVE,
  TIMER_OUTPUT_COMPARE_INACTIVE,
  TIMER_OUTPUT_COMPARE_TOGGLE,
  TIMER_OUTPUT_COMPARE_PWM1,
  TIMER_OUTPUT_COMPARE_PWM2,
  TIMER_OUTPUT_COMPARE_FORCED_ACTIVE,
  TIMER_OUTPUT_COMPARE_FORCED_INACTIVE,
  TIMER_INPUT_CAPTURE_RISING,
  TIMER_INPUT_CAPTURE_FALLING,
  TIMER_INPUT_CAPTURE_BOTHEDGE,
  TIMER_INPUT_FREQ_DUTY_MEASUREMENT,
  TIMER_NOT_USED = 0xFFFF
} TimerModes_t;
#define TIMER_DISABLED TIMER_OUTPUT_DISABLED
#define TIMER_OUTPUT_COMPARE TIMER_OUTPUT_DISABLED

/* How an overflow or a count is given: timer ticks (after the prescaler), microseconds, Hz. */
typedef enum { TICK_FORMAT, MICROSEC_FORMAT, HERTZ_FORMAT } TimerFormat_t;

/* How a compare value is given: a duty cycle at N bits of resolution, ticks, µs, Hz, percent. */
typedef enum {
  RESOLUTION_1B_COMPARE_FORMAT = 1, RESOLUTION_2B_COMPARE_FORMAT, RESOLUTION_3B_COMPARE_FORMAT,
  RESOLUTION_4B_COMPARE_FORMAT, RESOLUTION_5B_COMPARE_FORMAT, RESOLUTION_6B_COMPARE_FORMAT,
  RESOLUTION_7B_COMPARE_FORMAT, RESOLUTION_8B_COMPARE_FORMAT, RESOLUTION_9B_COMPARE_FORMAT,
  RESOLUTION_10B_COMPARE_FORMAT, RESOLUTION_11B_COMPARE_FORMAT, RESOLUTION_12B_COMPARE_FORMAT,
  RESOLUTION_13B_COMPARE_FORMAT, RESOLUTION_14B_COMPARE_FORMAT, RESOLUTION_15B_COMPARE_FORMAT,
  RESOLUTION_16B_COMPARE_FORMAT,
  TICK_COMPARE_FORMAT = 0x80,
  MICROSEC_COMPARE_FORMAT,
  HERTZ_COMPARE_FORMAT,
  PERCENT_COMPARE_FORMAT
} TimerCompareFormat_t;

/* Input filters (input capture is not modelled; the names are for setMode's signature). */
typedef enum { FILTER_NONE = 0 } ChannelInputFilter_t;

using callback_function_t = std::function<void(void)>;

/* One timer instance. Its counter runs at 84 MHz / prescale factor; overflow is ARR + 1 ticks.
 * A period or compare changed while it runs takes effect at the next update (preload on, as
 * STM32duino sets it); a callback runs at the exact virtual tick of its event. */
class HardwareTimer {
 public:
  /* A timer not yet bound to an instance (setup() binds it). */
  HardwareTimer();
  /* The timer `instance` (TIM1 ... TIM17), stopped: prescale factor 1, overflow 65536 ticks. */
  explicit HardwareTimer(TIM_TypeDef* instance);
  /* Stops it. */
  ~HardwareTimer();
  /* Binds a default-made timer to `instance`. */
  void setup(TIM_TypeDef* instance);

  /* Stops the counter and every channel (outputs low). */
  void pause(void);
  /* Disables channel `channel`'s output and compare callback; the counter runs on. */
  void pauseChannel(uint32_t channel);
  /* Starts the counter (from where it stands: 0 after setup) and every configured channel. */
  void resume(void);
  /* Re-enables channel `channel` (its output's next pulse at the next counter reset). */
  void resumeChannel(uint32_t channel);

  /* The prescale factor (PSC + 1, 1..65536). */
  void setPrescaleFactor(uint32_t prescaler);
  uint32_t getPrescaleFactor();

  /* The period: `val` ticks (ARR = val - 1), or microseconds / Hz, for which the prescaler is
   * chosen as STM32duino does (the smallest giving an ARR of 16 bits). */
  void setOverflow(uint32_t val, TimerFormat_t format = TICK_FORMAT);
  uint32_t getOverflow(TimerFormat_t format = TICK_FORMAT);

  /* Channel `channel` in PWM1 on `pin` at `frequency` Hz and `dutycycle` percent, with an
   * optional update and compare callback, and the timer resumed. */
  void setPWM(uint32_t channel, PinName pin, uint32_t frequency, uint32_t dutycycle,
              callback_function_t PeriodCallback = nullptr, callback_function_t CompareCallback = nullptr);
  void setPWM(uint32_t channel, uint32_t pin, uint32_t frequency, uint32_t dutycycle,
              callback_function_t PeriodCallback = nullptr, callback_function_t CompareCallback = nullptr);

  /* The counter, in ticks or the other formats. */
  void setCount(uint32_t val, TimerFormat_t format = TICK_FORMAT);
  uint32_t getCount(TimerFormat_t format = TICK_FORMAT);

  /* Channel `channel`'s mode and the pin it outputs on (NC: none). */
  void setMode(uint32_t channel, TimerModes_t mode, PinName pin = NC, ChannelInputFilter_t filter = FILTER_NONE);
  void setMode(uint32_t channel, TimerModes_t mode, uint32_t pin, ChannelInputFilter_t filter = FILTER_NONE);
  TimerModes_t getMode(uint32_t channel);

  /* Whether a new overflow or compare waits for the next update (true, the default) or applies
   * to the period under way. */
  void setPreloadEnable(bool value);

  /* Channel `channel`'s compare value (CCR) in ticks, or a duty cycle in the other formats. */
  uint32_t getCaptureCompare(uint32_t channel, TimerCompareFormat_t format = TICK_COMPARE_FORMAT);
  void setCaptureCompare(uint32_t channel, uint32_t compare, TimerCompareFormat_t format = TICK_COMPARE_FORMAT);

  /* Accepted and ignored: interrupts have no priorities here. */
  void setInterruptPriority(uint32_t preemptPriority, uint32_t subPriority);

  /* The update (overflow) callback. */
  void attachInterrupt(callback_function_t callback);
  void detachInterrupt();
  bool hasInterrupt();
  /* Channel `channel`'s compare-match callback. */
  void attachInterrupt(uint32_t channel, callback_function_t callback);
  void detachInterrupt(uint32_t channel);
  bool hasInterrupt(uint32_t channel);
  /* Stops the timer and forgets its callbacks. */
  void timerHandleDeinit();

  /* An update event now: the counter restarts from 0 with the new overflow and compares. */
  void refresh(void);

  /* The timer's input clock, Hz (84 MHz). */
  uint32_t getTimerClkFreq();

  /* Whether the counter runs; whether channel `channel` outputs while it does. */
  bool isRunning();
  bool isRunningChannel(uint32_t channel);

 private:
  void apply_channels();
  int timer_ = -1;       /* the runtime's timer */
  int update_irq_ = -1;  /* its interrupts */
  int compare_irq_ = -1;
  int compare_channel_ = -1; /* the channel whose compare the runtime's timer has */
  uint32_t number_ = 0;  /* TIMx's x */
  uint32_t prescale_ = 1;
  uint32_t overflow_ = 65536;
  TimerModes_t mode_[TIMER_CHANNELS] = {TIMER_NOT_USED, TIMER_NOT_USED, TIMER_NOT_USED, TIMER_NOT_USED};
  PinName pin_[TIMER_CHANNELS] = {NC, NC, NC, NC};
  uint32_t compare_[TIMER_CHANNELS] = {0, 0, 0, 0};
  bool channel_on_[TIMER_CHANNELS] = {false, false, false, false};
  callback_function_t callbacks_[1 + TIMER_CHANNELS];
};

#endif /* __cplusplus */

#endif /* L6470EMU_HARDWARE_TIMER_H */
