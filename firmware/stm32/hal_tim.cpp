// The STM32Cube HAL's TIM over the runtime's timers (firmware/timers.hpp): handles, channels,
// interrupt enables and flags, the NVIC vectors of the F401's timers, and which pin a channel
// outputs on (the alternate function HAL_GPIO_Init gave it).
// The model first: stm32_hal.h's macros (RESET, SET, ERROR, ...) must not reach its headers.
#include "firmware/runtime.hpp"
#include "firmware/stm32/hal_internal.hpp"
#include "firmware/timer_pins.hpp"

#include <array>
#include <string>
#include <vector>

#include "stm32_hal.h"

using l6470emu::FirmwareFront;
using l6470emu::FirmwareRuntime;
using l6470emu::FirmwareTimers;

TIM_TypeDef l6470emu_tim_instances[18] = {{0}, {1}, {2}, {3}, {4}, {5}, {6}, {7}, {8}, {9}, {10}, {11}, {12}, {13}, {14}, {15}, {16}, {17}};

namespace {

struct HalTimer {
  int timer = -1;                   // the runtime's timer
  TIM_HandleTypeDef* handle = nullptr;  // the handle last initialised for it
  std::array<std::uint32_t, 4> ccr{};
  std::array<std::uint32_t, 4> mode{};  // TIM_OCMODE_* per channel
  std::array<bool, 4> channel_on{};
  bool base_on = false;             // started by HAL_TIM_Base_Start / __HAL_TIM_ENABLE
  std::uint32_t it = 0;             // DIER: the TIM_IT_* enabled
  std::uint32_t flags = 0;          // SR: the TIM_FLAG_* pending
  int update_irq = -1, compare_irq = -1;  // the runtime interrupts of its NVIC vectors
  int compare_channel = -1;         // the channel whose compare the runtime's timer has
};
std::array<HalTimer, 18> g_tim;
std::vector<l6470emu::TimerPin> g_pins;  // port pins given a timer's alternate function

FirmwareRuntime& rt() { return l6470emu::firmware_runtime(FirmwareFront::stm32_hal); }

FirmwareRuntime& call() {
  FirmwareRuntime& r = rt();
  r.call();
  return r;
}

/// The timer's number (1..17) behind a handle, or 0 with one line when it has none.
unsigned number_of(const TIM_HandleTypeDef* h) {
  if (!h || !h->Instance || h->Instance < &l6470emu_tim_instances[1] || h->Instance > &l6470emu_tim_instances[17]) {
    rt().log("HAL TIM: a handle whose Instance is none of TIM1 to TIM17: ignored");
    return 0;
  }
  return h->Instance->l6470emu_number;
}

unsigned channel_index(std::uint32_t channel) { return (channel >> 2) & 3u; }

void run_vector(unsigned n, bool update);

HalTimer& timer_of(unsigned n) {
  HalTimer& t = g_tim[n];
  if (t.timer < 0) {
    FirmwareRuntime& r = rt();
    FirmwareTimers& timers = r.timers();
    const std::string name = "TIM" + std::to_string(n);
    t.timer = timers.find(name) >= 0 ? timers.find(name) : timers.add(name);
    timers.set_clock(t.timer, l6470emu::kF401TimerClockHz);
    t.update_irq = r.add_irq([n] {
      g_tim[n].flags |= TIM_FLAG_UPDATE;
      run_vector(n, true);
    });
    t.compare_irq = r.add_irq([n] {
      HalTimer& h = g_tim[n];
      if (h.compare_channel >= 0) h.flags |= TIM_FLAG_CC1 << h.compare_channel;
      run_vector(n, false);
    });
    r.set_irq_enabled(t.update_irq, false);  // until HAL_NVIC_EnableIRQ
    r.set_irq_enabled(t.compare_irq, false);
  }
  return t;
}

/// The channels' state onto the runtime's timer: the output pin, its compare, the interrupts.
void apply(unsigned n) {
  HalTimer& t = timer_of(n);
  FirmwareTimers& timers = rt().timers();
  int out = -1, out_key = -1;
  for (unsigned c = 0; c < 4; ++c) {
    if (!t.channel_on[c]) continue;
    for (const l6470emu::TimerPin& p : g_pins)
      if (p.timer == n && p.channel == c + 1) {
        out = static_cast<int>(c);
        out_key = 128 + p.port_pin;
      }
  }
  t.compare_channel = out;
  if (t.compare_channel < 0)
    for (unsigned c = 0; c < 4 && t.compare_channel < 0; ++c)
      if (t.channel_on[c] && (t.it & (TIM_IT_CC1 << c))) t.compare_channel = static_cast<int>(c);
  std::uint64_t compare = 0;
  if (t.compare_channel >= 0) {
    const auto c = static_cast<std::size_t>(t.compare_channel);
    const std::uint64_t period = timers.period(t.timer);
    compare = t.mode[c] == TIM_OCMODE_PWM2 ? (t.ccr[c] >= period ? 0 : period - t.ccr[c]) : t.ccr[c];
  }
  timers.set_compare(t.timer, compare);
  timers.set_output(t.timer, out_key);
  timers.set_update_irq(t.timer, (t.it & TIM_IT_UPDATE) ? t.update_irq : -1);
  const bool compare_it = t.compare_channel >= 0 && (t.it & (TIM_IT_CC1 << t.compare_channel));
  timers.set_compare_irq(t.timer, compare_it ? t.compare_irq : -1);
}

void run_counter(unsigned n) {
  HalTimer& t = timer_of(n);
  bool any = t.base_on;
  for (const bool on : t.channel_on) any = any || on;
  if (any)
    rt().timers().start(t.timer);
  else
    rt().timers().stop(t.timer);
}

void run_vector(unsigned n, bool update) {
  switch (n) {
    case 1: return update ? TIM1_UP_TIM10_IRQHandler() : TIM1_CC_IRQHandler();
    case 2: return TIM2_IRQHandler();
    case 3: return TIM3_IRQHandler();
    case 4: return TIM4_IRQHandler();
    case 5: return TIM5_IRQHandler();
    case 9: return TIM1_BRK_TIM9_IRQHandler();
    case 10: return TIM1_UP_TIM10_IRQHandler();
    case 11: return TIM1_TRG_COM_TIM11_IRQHandler();
    default:
      if (g_tim[n].handle) HAL_TIM_IRQHandler(g_tim[n].handle);  // a timer the F401 lacks: no vector
  }
}

void handle_if_pending(unsigned n) {
  if (g_tim[n].handle && g_tim[n].flags) HAL_TIM_IRQHandler(g_tim[n].handle);
}

HAL_StatusTypeDef init(TIM_HandleTypeDef* htim, bool pwm) {
  const unsigned n = number_of(htim);
  call();
  if (!n) return HAL_ERROR;
  HalTimer& t = timer_of(n);
  if (htim->State == HAL_TIM_STATE_RESET) {
    htim->Lock = HAL_UNLOCKED;
    pwm ? HAL_TIM_PWM_MspInit(htim) : HAL_TIM_Base_MspInit(htim);
  }
  t.handle = htim;
  if (htim->Init.CounterMode != TIM_COUNTERMODE_UP)
    rt().log("HAL TIM: TIM" + std::to_string(n) + " counts up here (CounterMode " + std::to_string(htim->Init.CounterMode) +
             " is not modelled)");
  FirmwareTimers& timers = rt().timers();
  timers.set_prescaler(t.timer, htim->Init.Prescaler + 1);
  timers.set_period(t.timer, static_cast<std::uint64_t>(htim->Init.Period) + 1);
  timers.set_preload(t.timer, htim->Init.AutoReloadPreload == TIM_AUTORELOAD_PRELOAD_ENABLE);
  htim->State = HAL_TIM_STATE_READY;
  return HAL_OK;
}

HAL_StatusTypeDef channel_start(TIM_HandleTypeDef* htim, uint32_t channel, bool on, bool with_it) {
  const unsigned n = number_of(htim);
  call();
  if (!n) return HAL_ERROR;
  HalTimer& t = timer_of(n);
  const unsigned c = channel_index(channel);
  t.channel_on[c] = on;
  if (with_it) t.it = on ? t.it | (TIM_IT_CC1 << c) : t.it & ~(TIM_IT_CC1 << c);
  apply(n);
  run_counter(n);
  return HAL_OK;
}

HAL_StatusTypeDef base_start(TIM_HandleTypeDef* htim, bool on, bool with_it) {
  const unsigned n = number_of(htim);
  call();
  if (!n) return HAL_ERROR;
  HalTimer& t = timer_of(n);
  t.base_on = on;
  if (with_it) t.it = on ? t.it | TIM_IT_UPDATE : t.it & ~TIM_IT_UPDATE;
  apply(n);
  run_counter(n);
  return HAL_OK;
}

}  // namespace

// ---------------------------------------------------------------- stm32_hal.h's hooks

bool l6470emu_tim_gpio_af(unsigned port_pin, std::uint32_t alternate) {
  // The pin leaves the timer it was given to (its output stops driving it), if any.
  for (auto it = g_pins.begin(); it != g_pins.end();) {
    if (it->port_pin != port_pin) {
      ++it;
      continue;
    }
    const unsigned timer = it->timer;
    it = g_pins.erase(it);
    if (g_tim[timer].timer >= 0) apply(timer);
  }
  for (unsigned timer = 1; timer <= 11; ++timer)
    if (const auto p = l6470emu::timer_pin(port_pin, timer, alternate)) {
      g_pins.push_back(*p);
      if (g_tim[timer].timer >= 0) apply(timer);
      return true;
    }
  return false;
}

bool l6470emu_tim_nvic(int irqn, bool enable) {
  std::vector<std::pair<unsigned, bool>> sources;  // (timer, update) the vector serves
  switch (irqn) {
    case TIM1_UP_TIM10_IRQn: sources = {{1, true}, {10, true}, {10, false}}; break;
    case TIM1_CC_IRQn: sources = {{1, false}}; break;
    case TIM1_BRK_TIM9_IRQn: sources = {{9, true}, {9, false}}; break;
    case TIM1_TRG_COM_TIM11_IRQn: sources = {{11, true}, {11, false}}; break;
    case TIM2_IRQn: case TIM3_IRQn: case TIM4_IRQn: {
      const unsigned n = static_cast<unsigned>(irqn - TIM2_IRQn + 2);
      sources = {{n, true}, {n, false}};
      break;
    }
    case TIM5_IRQn: sources = {{5, true}, {5, false}}; break;
    default: return false;
  }
  for (const auto& [n, update] : sources) {
    HalTimer& t = timer_of(n);
    rt().set_irq_enabled(update ? t.update_irq : t.compare_irq, enable);
  }
  return true;
}

extern "C" {

// ---------------------------------------------------------------- set-up

HAL_StatusTypeDef HAL_TIM_Base_Init(TIM_HandleTypeDef* htim) { return init(htim, false); }
HAL_StatusTypeDef HAL_TIM_PWM_Init(TIM_HandleTypeDef* htim) { return init(htim, true); }

HAL_StatusTypeDef HAL_TIM_Base_DeInit(TIM_HandleTypeDef* htim) {
  const unsigned n = number_of(htim);
  call();
  if (!n) return HAL_ERROR;
  HalTimer& t = timer_of(n);
  t.channel_on.fill(false);
  t.base_on = false;
  t.it = 0;
  apply(n);
  run_counter(n);
  HAL_TIM_Base_MspDeInit(htim);
  htim->State = HAL_TIM_STATE_RESET;
  return HAL_OK;
}

HAL_StatusTypeDef HAL_TIM_PWM_DeInit(TIM_HandleTypeDef* htim) { return HAL_TIM_Base_DeInit(htim); }

__weak void HAL_TIM_Base_MspInit(TIM_HandleTypeDef*) {}
__weak void HAL_TIM_Base_MspDeInit(TIM_HandleTypeDef*) {}
__weak void HAL_TIM_PWM_MspInit(TIM_HandleTypeDef*) {}
__weak void HAL_TIM_PWM_MspDeInit(TIM_HandleTypeDef*) {}

HAL_StatusTypeDef HAL_TIM_ConfigClockSource(TIM_HandleTypeDef*, TIM_ClockConfigTypeDef*) {
  call();
  return HAL_OK;
}

HAL_StatusTypeDef HAL_TIMEx_MasterConfigSynchronization(TIM_HandleTypeDef*, TIM_MasterConfigTypeDef*) {
  call();
  return HAL_OK;
}

HAL_StatusTypeDef HAL_TIM_PWM_ConfigChannel(TIM_HandleTypeDef* htim, TIM_OC_InitTypeDef* sConfig, uint32_t Channel) {
  const unsigned n = number_of(htim);
  call();
  if (!n || !sConfig) return HAL_ERROR;
  HalTimer& t = timer_of(n);
  const unsigned c = channel_index(Channel);
  if (sConfig->OCMode != TIM_OCMODE_PWM1 && sConfig->OCMode != TIM_OCMODE_PWM2)
    rt().log("HAL TIM: TIM" + std::to_string(n) + " channel " + std::to_string(c + 1) +
             ": only PWM1 and PWM2 drive a pin here");
  t.mode[c] = sConfig->OCMode;
  t.ccr[c] = sConfig->Pulse;
  apply(n);
  return HAL_OK;
}

// ---------------------------------------------------------------- start and stop

HAL_StatusTypeDef HAL_TIM_Base_Start(TIM_HandleTypeDef* htim) { return base_start(htim, true, false); }
HAL_StatusTypeDef HAL_TIM_Base_Stop(TIM_HandleTypeDef* htim) { return base_start(htim, false, false); }
HAL_StatusTypeDef HAL_TIM_Base_Start_IT(TIM_HandleTypeDef* htim) { return base_start(htim, true, true); }
HAL_StatusTypeDef HAL_TIM_Base_Stop_IT(TIM_HandleTypeDef* htim) { return base_start(htim, false, true); }
HAL_StatusTypeDef HAL_TIM_PWM_Start(TIM_HandleTypeDef* htim, uint32_t Channel) { return channel_start(htim, Channel, true, false); }
HAL_StatusTypeDef HAL_TIM_PWM_Stop(TIM_HandleTypeDef* htim, uint32_t Channel) { return channel_start(htim, Channel, false, false); }
HAL_StatusTypeDef HAL_TIM_PWM_Start_IT(TIM_HandleTypeDef* htim, uint32_t Channel) { return channel_start(htim, Channel, true, true); }
HAL_StatusTypeDef HAL_TIM_PWM_Stop_IT(TIM_HandleTypeDef* htim, uint32_t Channel) { return channel_start(htim, Channel, false, true); }

HAL_TIM_StateTypeDef HAL_TIM_Base_GetState(TIM_HandleTypeDef* htim) { return htim ? htim->State : HAL_TIM_STATE_RESET; }

// ---------------------------------------------------------------- interrupts

void HAL_TIM_IRQHandler(TIM_HandleTypeDef* htim) {
  const unsigned n = number_of(htim);
  if (!n) return;
  HalTimer& t = g_tim[n];
  for (unsigned c = 0; c < 4; ++c) {
    const std::uint32_t bit = TIM_FLAG_CC1 << c;
    if (!(t.flags & bit) || !(t.it & bit)) continue;
    t.flags &= ~bit;
    htim->Channel = static_cast<HAL_TIM_ActiveChannel>(1u << c);
    HAL_TIM_PWM_PulseFinishedCallback(htim);
    HAL_TIM_OC_DelayElapsedCallback(htim);
    htim->Channel = HAL_TIM_ACTIVE_CHANNEL_CLEARED;
  }
  if ((t.flags & TIM_FLAG_UPDATE) && (t.it & TIM_IT_UPDATE)) {
    t.flags &= ~TIM_FLAG_UPDATE;
    HAL_TIM_PeriodElapsedCallback(htim);
  }
}

__weak void HAL_TIM_PeriodElapsedCallback(TIM_HandleTypeDef*) {}
__weak void HAL_TIM_PWM_PulseFinishedCallback(TIM_HandleTypeDef*) {}
__weak void HAL_TIM_OC_DelayElapsedCallback(TIM_HandleTypeDef*) {}

__weak void TIM1_UP_TIM10_IRQHandler(void) {
  handle_if_pending(1);
  handle_if_pending(10);
}
__weak void TIM1_CC_IRQHandler(void) { handle_if_pending(1); }
__weak void TIM1_BRK_TIM9_IRQHandler(void) { handle_if_pending(9); }
__weak void TIM1_TRG_COM_TIM11_IRQHandler(void) { handle_if_pending(11); }
__weak void TIM2_IRQHandler(void) { handle_if_pending(2); }
__weak void TIM3_IRQHandler(void) { handle_if_pending(3); }
__weak void TIM4_IRQHandler(void) { handle_if_pending(4); }
__weak void TIM5_IRQHandler(void) { handle_if_pending(5); }

// ---------------------------------------------------------------- the registers' macros

void l6470emu_tim_set_autoreload(TIM_HandleTypeDef* htim, uint32_t value) {
  const unsigned n = number_of(htim);
  call();
  if (!n) return;
  htim->Init.Period = value;
  rt().timers().set_period(timer_of(n).timer, static_cast<std::uint64_t>(value) + 1);
  apply(n);  // a PWM2 compare is counted from the period
}

uint32_t l6470emu_tim_get_autoreload(TIM_HandleTypeDef* htim) { return htim ? htim->Init.Period : 0; }

void l6470emu_tim_set_compare(TIM_HandleTypeDef* htim, uint32_t channel, uint32_t value) {
  const unsigned n = number_of(htim);
  call();
  if (!n) return;
  timer_of(n).ccr[channel_index(channel)] = value;
  apply(n);
}

uint32_t l6470emu_tim_get_compare(TIM_HandleTypeDef* htim, uint32_t channel) {
  const unsigned n = number_of(htim);
  return n ? g_tim[n].ccr[channel_index(channel)] : 0;
}

void l6470emu_tim_set_prescaler(TIM_HandleTypeDef* htim, uint32_t value) {
  const unsigned n = number_of(htim);
  call();
  if (!n) return;
  htim->Init.Prescaler = value;
  rt().timers().set_prescaler(timer_of(n).timer, value + 1);
}

void l6470emu_tim_set_counter(TIM_HandleTypeDef* htim, uint32_t value) {
  const unsigned n = number_of(htim);
  call();
  if (n) rt().timers().set_counter(timer_of(n).timer, value);
}

uint32_t l6470emu_tim_get_counter(TIM_HandleTypeDef* htim) {
  const unsigned n = number_of(htim);
  call();
  return n ? static_cast<uint32_t>(rt().timers().counter(timer_of(n).timer)) : 0;
}

void l6470emu_tim_enable(TIM_HandleTypeDef* htim, int on) { base_start(htim, on != 0, false); }

void l6470emu_tim_enable_it(TIM_HandleTypeDef* htim, uint32_t it, int on) {
  const unsigned n = number_of(htim);
  call();
  if (!n) return;
  HalTimer& t = timer_of(n);
  t.it = on ? t.it | it : t.it & ~it;
  apply(n);
}

uint32_t l6470emu_tim_flags(TIM_HandleTypeDef* htim) {
  const unsigned n = number_of(htim);
  return n ? g_tim[n].flags : 0;
}

void l6470emu_tim_clear_flags(TIM_HandleTypeDef* htim, uint32_t flags) {
  const unsigned n = number_of(htim);
  if (n) g_tim[n].flags &= ~flags;
}

}  // extern "C"
