/* An STM32Cube HAL program stepping an L6474 (X-NUCLEO-IHM01A1 wiring on a NUCLEO-F401RE) from
 * a timer, laid out as CubeMX lays one out: TIM3 at 1 MHz counts (Prescaler 83 of 84 MHz),
 * Period 999 (1 kHz), channel 2 PWM1 with Pulse 500 on PC7 (D9, AF2_TIM3, the board's STCK),
 * its NVIC vector enabled in HAL_TIM_Base_MspInit and HAL_TIM_PeriodElapsedCallback counting.
 * Checks: each callback runs at its exact tick (the counter it reads is 1 count: its own call's
 * 1 us); the callback stopping the PWM at the 1000th update leaves ABS_POS at 1001 pulses; a
 * PWM without interrupts for 10 simulated minutes moves it by exactly 600000 more; a period
 * and compare written with __HAL_TIM_SET_AUTORELOAD and _COMPARE (preload on) take effect at the
 * next update. Prints PASS. */
#include <stdio.h>
#include <stdlib.h>

#include "stm32f4xx_hal.h"

SPI_HandleTypeDef hspi1;
TIM_HandleTypeDef htim3;
static volatile uint32_t updates = 0;
static volatile uint32_t stop_at = 1000;
static uint32_t first_counters[3];
static int failures = 0;

static void check(int ok, const char* what) {
  printf("%s %s\n", ok ? "ok  " : "FAIL", what);
  if (!ok) ++failures;
}

void Error_Handler(void) {
  printf("FAIL Error_Handler\n");
  exit(1);
}

void HAL_TIM_Base_MspInit(TIM_HandleTypeDef* htim) {
  if (htim->Instance != TIM3) return;
  GPIO_InitTypeDef gpio = {0};
  __HAL_RCC_TIM3_CLK_ENABLE();
  gpio.Pin = GPIO_PIN_7;
  gpio.Mode = GPIO_MODE_AF_PP;
  gpio.Pull = GPIO_NOPULL;
  gpio.Speed = GPIO_SPEED_FREQ_LOW;
  gpio.Alternate = GPIO_AF2_TIM3;
  HAL_GPIO_Init(GPIOC, &gpio);
  HAL_NVIC_SetPriority(TIM3_IRQn, 0, 0);
  HAL_NVIC_EnableIRQ(TIM3_IRQn);
}

/* stm32f4xx_it.c */
void TIM3_IRQHandler(void) { HAL_TIM_IRQHandler(&htim3); }

void HAL_TIM_PeriodElapsedCallback(TIM_HandleTypeDef* htim) {
  if (htim->Instance != TIM3) return;
  if (updates < 3) first_counters[updates] = __HAL_TIM_GET_COUNTER(htim);
  if (++updates == stop_at) {
    HAL_TIM_PWM_Stop(htim, TIM_CHANNEL_2);
    HAL_TIM_Base_Stop_IT(htim);
  }
}

static void MX_TIM3_Init(void) {
  TIM_OC_InitTypeDef oc = {0};
  htim3.Instance = TIM3;
  htim3.Init.Prescaler = 83;
  htim3.Init.CounterMode = TIM_COUNTERMODE_UP;
  htim3.Init.Period = 999;
  htim3.Init.ClockDivision = TIM_CLOCKDIVISION_DIV1;
  htim3.Init.AutoReloadPreload = TIM_AUTORELOAD_PRELOAD_ENABLE;
  if (HAL_TIM_Base_Init(&htim3) != HAL_OK) Error_Handler();
  if (HAL_TIM_PWM_Init(&htim3) != HAL_OK) Error_Handler();
  oc.OCMode = TIM_OCMODE_PWM1;
  oc.Pulse = 500;
  oc.OCPolarity = TIM_OCPOLARITY_HIGH;
  oc.OCFastMode = TIM_OCFAST_DISABLE;
  if (HAL_TIM_PWM_ConfigChannel(&htim3, &oc, TIM_CHANNEL_2) != HAL_OK) Error_Handler();
}

static void MX_SPI1_Init(void) {
  hspi1.Instance = SPI1;
  hspi1.Init.Mode = SPI_MODE_MASTER;
  hspi1.Init.Direction = SPI_DIRECTION_2LINES;
  hspi1.Init.DataSize = SPI_DATASIZE_8BIT;
  hspi1.Init.CLKPolarity = SPI_POLARITY_HIGH;
  hspi1.Init.CLKPhase = SPI_PHASE_2EDGE;
  hspi1.Init.NSS = SPI_NSS_SOFT;
  hspi1.Init.BaudRatePrescaler = SPI_BAUDRATEPRESCALER_32;
  hspi1.Init.FirstBit = SPI_FIRSTBIT_MSB;
  if (HAL_SPI_Init(&hspi1) != HAL_OK) Error_Handler();
}

static uint8_t xfer(uint8_t b) {
  uint8_t in = 0;
  HAL_GPIO_WritePin(GPIOB, GPIO_PIN_6, GPIO_PIN_RESET);
  if (HAL_SPI_TransmitReceive(&hspi1, &b, &in, 1, 10) != HAL_OK) Error_Handler();
  HAL_GPIO_WritePin(GPIOB, GPIO_PIN_6, GPIO_PIN_SET);
  return in;
}

static long abs_pos(void) {
  xfer(0x21); /* GetParam(ABS_POS) */
  long v = (long)xfer(0) << 16;
  v |= (long)xfer(0) << 8;
  v |= xfer(0);
  return (v & 0x200000) ? v - 0x400000 : v;
}

int main(void) {
  GPIO_InitTypeDef gpio = {0};
  HAL_Init();
  __HAL_RCC_GPIOA_CLK_ENABLE();
  __HAL_RCC_GPIOB_CLK_ENABLE();
  __HAL_RCC_GPIOC_CLK_ENABLE();
  HAL_GPIO_WritePin(GPIOB, GPIO_PIN_6, GPIO_PIN_SET); /* CS (D10) */
  HAL_GPIO_WritePin(GPIOA, GPIO_PIN_8, GPIO_PIN_SET); /* DIR (D7): forward */
  gpio.Pin = GPIO_PIN_6;
  gpio.Mode = GPIO_MODE_OUTPUT_PP;
  HAL_GPIO_Init(GPIOB, &gpio);
  gpio.Pin = GPIO_PIN_8;
  HAL_GPIO_Init(GPIOA, &gpio);
  MX_SPI1_Init();
  MX_TIM3_Init();
  xfer(0xB8); /* Enable */

  HAL_TIM_PWM_Start(&htim3, TIM_CHANNEL_2);
  HAL_TIM_Base_Start_IT(&htim3);
  HAL_Delay(1500);
  check(updates == 1000, "1000 update callbacks, then the PWM stopped from the last one");
  check(first_counters[0] == 1 && first_counters[1] == 1 && first_counters[2] == 1,
        "each callback reads the counter 1 count (1 us) after its update");
  check(abs_pos() == 1001, "ABS_POS moved by the 1001 pulses (the stopping update's own pulse rose first)");

  /* Ten simulated minutes at 1 kHz without interrupts: no callback, so no event per pulse. */
  HAL_TIM_PWM_Start(&htim3, TIM_CHANNEL_2);
  HAL_Delay(600000 - 1);
  HAL_TIM_PWM_Stop(&htim3, TIM_CHANNEL_2);
  check(abs_pos() == 1001 + 600000, "1 kHz for 10 minutes: exactly 600000 pulses");

  /* A new period with the preload on: in force from the next update. */
  updates = 0;
  stop_at = 4;
  HAL_TIM_PWM_Start(&htim3, TIM_CHANNEL_2);
  HAL_TIM_Base_Start_IT(&htim3);
  __HAL_TIM_SET_AUTORELOAD(&htim3, 499); /* 2 kHz, from the update at 1 ms on */
  __HAL_TIM_SET_COMPARE(&htim3, TIM_CHANNEL_2, 250); /* (a CCR of 500 would keep the pin high) */
  check(__HAL_TIM_GET_AUTORELOAD(&htim3) == 499 && __HAL_TIM_GET_COMPARE(&htim3, TIM_CHANNEL_2) == 250,
        "__HAL_TIM_GET_AUTORELOAD and _COMPARE read what was set");
  HAL_Delay(10);
  /* Updates at 1 ms (the period under way keeps 1000 us), 1.5, 2 and 2.5 ms, the 4th stopping
   * it: pulses at 0, 1, 1.5, 2 and 2.5 ms. */
  check(abs_pos() == 1001 + 600000 + 5, "the new period from the next update: 5 pulses to the 4th update");
  printf("%s\n", failures ? "FAIL" : "PASS");
  return failures ? 1 : 0;
}
