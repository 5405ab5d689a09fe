/* The STM32Cube HAL's TIM as drivers of step-clock parts use it (docs/firmware.md, "Timers"):
 * base and PWM init, PWM channels started with or without interrupts, the period and compare
 * macros, update and compare callbacks at their exact virtual ticks through the timer's NVIC
 * vector. A channel's output is the pin HAL_GPIO_Init gave that timer's alternate function
 * (the F401's table: firmware/timer_pins.hpp); a pin wired to STCK then takes the PWM as a
 * pulse train. The timers count 84 MHz (a NUCLEO-F401RE's timer clock) / (Prescaler + 1);
 * a period is Period + 1 counts. Not modelled: input capture, one-pulse and encoder modes,
 * output compare other than PWM1/PWM2, DMA, registers (TIM3->ARR), centre-aligned counting.
 * Included by stm32_hal.h. */
#ifndef L6470EMU_STM32_HAL_TIM_H
#define L6470EMU_STM32_HAL_TIM_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* A timer instance: TIM1 ... TIM17 are distinct addresses; nothing is behind them. */
typedef struct {
  uint32_t l6470emu_number; /* the x of TIMx */
} TIM_TypeDef;
extern TIM_TypeDef l6470emu_tim_instances[18];
#define TIM1 (&l6470emu_tim_instances[1])
#define TIM2 (&l6470emu_tim_instances[2])
#define TIM3 (&l6470emu_tim_instances[3])
#define TIM4 (&l6470emu_tim_instances[4])
#define TIM5 (&l6470emu_tim_instances[5])
#define TIM6 (&l6470emu_tim_instances[6])
#define TIM7 (&l6470emu_tim_instances[7])
#define TIM8 (&l6470emu_tim_instances[8])
#define TIM9 (&l6470emu_tim_instances[9])
#define TIM10 (&l6470emu_tim_instances[10])
#define TIM11 (&l6470emu_tim_instances[11])
#define TIM12 (&l6470emu_tim_instances[12])
#define TIM13 (&l6470emu_tim_instances[13])
#define TIM14 (&l6470emu_tim_instances[14])
#define TIM15 (&l6470emu_tim_instances[15])
#define TIM16 (&l6470emu_tim_instances[16])
#define TIM17 (&l6470emu_tim_instances[17])

/* The timers' alternate functions on the F401 (HAL_GPIO_Init's Alternate). */
#define GPIO_AF1_TIM1 0x01U
#define GPIO_AF1_TIM2 0x01U
#define GPIO_AF2_TIM3 0x02U
#define GPIO_AF2_TIM4 0x02U
#define GPIO_AF2_TIM5 0x02U
#define GPIO_AF3_TIM9 0x03U
#define GPIO_AF3_TIM10 0x03U
#define GPIO_AF3_TIM11 0x03U

typedef struct {
  uint32_t Prescaler;         /* PSC: the counter counts 84 MHz / (Prescaler + 1) */
  uint32_t CounterMode;       /* TIM_COUNTERMODE_UP only */
  uint32_t Period;            /* ARR: a period is Period + 1 counts */
  uint32_t ClockDivision;
  uint32_t RepetitionCounter;
  uint32_t AutoReloadPreload; /* TIM_AUTORELOAD_PRELOAD_ENABLE: a new ARR waits for the next update */
} TIM_Base_InitTypeDef;

typedef struct {
  uint32_t OCMode; /* TIM_OCMODE_PWM1 or _PWM2 */
  uint32_t Pulse;  /* CCR */
  uint32_t OCPolarity;
  uint32_t OCNPolarity;
  uint32_t OCFastMode;
  uint32_t OCIdleState;
  uint32_t OCNIdleState;
} TIM_OC_InitTypeDef;

typedef struct {
  uint32_t ClockSource;
  uint32_t ClockPolarity;
  uint32_t ClockPrescaler;
  uint32_t ClockFilter;
} TIM_ClockConfigTypeDef;

typedef struct {
  uint32_t MasterOutputTrigger;
  uint32_t MasterSlaveMode;
} TIM_MasterConfigTypeDef;

typedef enum {
  HAL_TIM_ACTIVE_CHANNEL_1 = 0x01U,
  HAL_TIM_ACTIVE_CHANNEL_2 = 0x02U,
  HAL_TIM_ACTIVE_CHANNEL_3 = 0x04U,
  HAL_TIM_ACTIVE_CHANNEL_4 = 0x08U,
  HAL_TIM_ACTIVE_CHANNEL_CLEARED = 0x00U
} HAL_TIM_ActiveChannel;

typedef enum {
  HAL_TIM_STATE_RESET = 0x00U,
  HAL_TIM_STATE_READY = 0x01U,
  HAL_TIM_STATE_BUSY = 0x02U,
  HAL_TIM_STATE_TIMEOUT = 0x03U,
  HAL_TIM_STATE_ERROR = 0x04U
} HAL_TIM_StateTypeDef;

typedef struct __TIM_HandleTypeDef {
  TIM_TypeDef* Instance;
  TIM_Base_InitTypeDef Init;
  HAL_TIM_ActiveChannel Channel; /* the channel whose compare a callback reports */
  HAL_LockTypeDef Lock;
  volatile HAL_TIM_StateTypeDef State;
} TIM_HandleTypeDef;

#define TIM_CHANNEL_1 0x00000000U
#define TIM_CHANNEL_2 0x00000004U
#define TIM_CHANNEL_3 0x00000008U
#define TIM_CHANNEL_4 0x0000000CU
#define TIM_CHANNEL_ALL 0x0000003CU
#define TIM_COUNTERMODE_UP 0x00000000U
#define TIM_CLOCKDIVISION_DIV1 0x00000000U
#define TIM_AUTORELOAD_PRELOAD_DISABLE 0x00000000U
#define TIM_AUTORELOAD_PRELOAD_ENABLE 0x00000080U
#define TIM_OCMODE_TIMING 0x00000000U
#define TIM_OCMODE_PWM1 0x00000060U
#define TIM_OCMODE_PWM2 0x00000070U
#define TIM_OCPOLARITY_HIGH 0x00000000U
#define TIM_OCPOLARITY_LOW 0x00000002U
#define TIM_OCNPOLARITY_HIGH 0x00000000U
#define TIM_OCFAST_DISABLE 0x00000000U
#define TIM_OCFAST_ENABLE 0x00000004U
#define TIM_OCIDLESTATE_RESET 0x00000000U
#define TIM_OCNIDLESTATE_RESET 0x00000000U
#define TIM_CLOCKSOURCE_INTERNAL 0x00000000U
#define TIM_TRGO_RESET 0x00000000U
#define TIM_MASTERSLAVEMODE_DISABLE 0x00000000U
#define TIM_IT_UPDATE 0x00000001U
#define TIM_IT_CC1 0x00000002U
#define TIM_IT_CC2 0x00000004U
#define TIM_IT_CC3 0x00000008U
#define TIM_IT_CC4 0x00000010U
#define TIM_FLAG_UPDATE TIM_IT_UPDATE
#define TIM_FLAG_CC1 TIM_IT_CC1
#define TIM_FLAG_CC2 TIM_IT_CC2
#define TIM_FLAG_CC3 TIM_IT_CC3
#define TIM_FLAG_CC4 TIM_IT_CC4

/* Set-up: the handle's Init taken (Base and PWM alike), the MspInit callbacks run (weak, empty). */
HAL_StatusTypeDef HAL_TIM_Base_Init(TIM_HandleTypeDef* htim);
HAL_StatusTypeDef HAL_TIM_Base_DeInit(TIM_HandleTypeDef* htim);
HAL_StatusTypeDef HAL_TIM_PWM_Init(TIM_HandleTypeDef* htim);
HAL_StatusTypeDef HAL_TIM_PWM_DeInit(TIM_HandleTypeDef* htim);
void HAL_TIM_Base_MspInit(TIM_HandleTypeDef* htim);
void HAL_TIM_Base_MspDeInit(TIM_HandleTypeDef* htim);
void HAL_TIM_PWM_MspInit(TIM_HandleTypeDef* htim);
void HAL_TIM_PWM_MspDeInit(TIM_HandleTypeDef* htim);
/* Accepted (the internal clock, no master/slave). */
HAL_StatusTypeDef HAL_TIM_ConfigClockSource(TIM_HandleTypeDef* htim, TIM_ClockConfigTypeDef* sClockSourceConfig);
HAL_StatusTypeDef HAL_TIMEx_MasterConfigSynchronization(TIM_HandleTypeDef* htim, TIM_MasterConfigTypeDef* sMasterConfig);
/* Channel `Channel` in PWM1/PWM2 with compare sConfig->Pulse. */
HAL_StatusTypeDef HAL_TIM_PWM_ConfigChannel(TIM_HandleTypeDef* htim, TIM_OC_InitTypeDef* sConfig, uint32_t Channel);

/* The counter started (update interrupt enabled with _IT) and stopped. */
HAL_StatusTypeDef HAL_TIM_Base_Start(TIM_HandleTypeDef* htim);
HAL_StatusTypeDef HAL_TIM_Base_Stop(TIM_HandleTypeDef* htim);
HAL_StatusTypeDef HAL_TIM_Base_Start_IT(TIM_HandleTypeDef* htim);
HAL_StatusTypeDef HAL_TIM_Base_Stop_IT(TIM_HandleTypeDef* htim);
/* The channel's output on and the counter started (its compare interrupt enabled with _IT);
 * _Stop turns the output off (low) and stops the counter unless another channel or the base
 * still uses it. */
HAL_StatusTypeDef HAL_TIM_PWM_Start(TIM_HandleTypeDef* htim, uint32_t Channel);
HAL_StatusTypeDef HAL_TIM_PWM_Stop(TIM_HandleTypeDef* htim, uint32_t Channel);
HAL_StatusTypeDef HAL_TIM_PWM_Start_IT(TIM_HandleTypeDef* htim, uint32_t Channel);
HAL_StatusTypeDef HAL_TIM_PWM_Stop_IT(TIM_HandleTypeDef* htim, uint32_t Channel);
HAL_TIM_StateTypeDef HAL_TIM_Base_GetState(TIM_HandleTypeDef* htim);

/* The timer's interrupt: for each pending flag whose interrupt is enabled, the flag cleared and
 * the callback run (update: PeriodElapsed; compare: PWM_PulseFinished and OC_DelayElapsed, with
 * htim->Channel set). The weak vector handlers below call it for the handle last initialised. */
void HAL_TIM_IRQHandler(TIM_HandleTypeDef* htim);
void HAL_TIM_PeriodElapsedCallback(TIM_HandleTypeDef* htim);
void HAL_TIM_PWM_PulseFinishedCallback(TIM_HandleTypeDef* htim);
void HAL_TIM_OC_DelayElapsedCallback(TIM_HandleTypeDef* htim);
void TIM1_UP_TIM10_IRQHandler(void);
void TIM1_CC_IRQHandler(void);
void TIM1_BRK_TIM9_IRQHandler(void);
void TIM1_TRG_COM_TIM11_IRQHandler(void);
void TIM2_IRQHandler(void);
void TIM3_IRQHandler(void);
void TIM4_IRQHandler(void);
void TIM5_IRQHandler(void);

/* The registers the macros below reach (no TIMx->ARR here: these functions instead). */
void l6470emu_tim_set_autoreload(TIM_HandleTypeDef* htim, uint32_t value);
uint32_t l6470emu_tim_get_autoreload(TIM_HandleTypeDef* htim);
void l6470emu_tim_set_compare(TIM_HandleTypeDef* htim, uint32_t channel, uint32_t value);
uint32_t l6470emu_tim_get_compare(TIM_HandleTypeDef* htim, uint32_t channel);
void l6470emu_tim_set_prescaler(TIM_HandleTypeDef* htim, uint32_t value);
void l6470emu_tim_set_counter(TIM_HandleTypeDef* htim, uint32_t value);
uint32_t l6470emu_tim_get_counter(TIM_HandleTypeDef* htim);
void l6470emu_tim_enable(TIM_HandleTypeDef* htim, int on);
void l6470emu_tim_enable_it(TIM_HandleTypeDef* htim, uint32_t it, int on);
uint32_t l6470emu_tim_flags(TIM_HandleTypeDef* htim);
void l6470emu_tim_clear_flags(TIM_HandleTypeDef* htim, uint32_t flags);

/* ARR and CCR as the HAL's macros write them (with the preload, from the next update on). */
#define __HAL_TIM_SET_AUTORELOAD(__HANDLE__, __AUTORELOAD__) l6470emu_tim_set_autoreload((__HANDLE__), (__AUTORELOAD__))
#define __HAL_TIM_GET_AUTORELOAD(__HANDLE__) l6470emu_tim_get_autoreload(__HANDLE__)
#define __HAL_TIM_SET_COMPARE(__HANDLE__, __CHANNEL__, __COMPARE__) \
  l6470emu_tim_set_compare((__HANDLE__), (__CHANNEL__), (__COMPARE__))
#define __HAL_TIM_GET_COMPARE(__HANDLE__, __CHANNEL__) l6470emu_tim_get_compare((__HANDLE__), (__CHANNEL__))
#define __HAL_TIM_SET_PRESCALER(__HANDLE__, __PRESC__) l6470emu_tim_set_prescaler((__HANDLE__), (__PRESC__))
#define __HAL_TIM_SET_COUNTER(__HANDLE__, __COUNTER__) l6470emu_tim_set_counter((__HANDLE__), (__COUNTER__))
#define __HAL_TIM_GET_COUNTER(__HANDLE__) l6470emu_tim_get_counter(__HANDLE__)
#define __HAL_TIM_ENABLE(__HANDLE__) l6470emu_tim_enable((__HANDLE__), 1)
#define __HAL_TIM_DISABLE(__HANDLE__) l6470emu_tim_enable((__HANDLE__), 0)
#define __HAL_TIM_ENABLE_IT(__HANDLE__, __INTERRUPT__) l6470emu_tim_enable_it((__HANDLE__), (__INTERRUPT__), 1)
#define __HAL_TIM_DISABLE_IT(__HANDLE__, __INTERRUPT__) l6470emu_tim_enable_it((__HANDLE__), (__INTERRUPT__), 0)
#define __HAL_TIM_GET_FLAG(__HANDLE__, __FLAG__) ((l6470emu_tim_flags(__HANDLE__) & (__FLAG__)) == (__FLAG__))
#define __HAL_TIM_CLEAR_FLAG(__HANDLE__, __FLAG__) l6470emu_tim_clear_flags((__HANDLE__), (__FLAG__))
#define __HAL_TIM_CLEAR_IT(__HANDLE__, __INTERRUPT__) l6470emu_tim_clear_flags((__HANDLE__), (__INTERRUPT__))

#ifdef __cplusplus
}
#endif

#endif /* L6470EMU_STM32_HAL_TIM_H */
