/* A complete STM32Cube HAL program for one L6470, laid out as CubeMX generates one: CS on PB6,
 * BUSY on PB3 (a NUCLEO board's Arduino D10 and D3: the HAL front's default pins), SPI1 in mode 3
 * (CPOL high, second edge), MSB first. It moves the motor 3200 microsteps, waits for BUSY and
 * prints where the motor is; run on the desktop in virtual time. */
#include <stdio.h>

#include "stm32f4xx_hal.h"

SPI_HandleTypeDef hspi1;

void Error_Handler(void) {
  printf("Error_Handler\n");
  for (;;) {
  }
}

static void MX_GPIO_Init(void) {
  GPIO_InitTypeDef gpio = {0};
  __HAL_RCC_GPIOB_CLK_ENABLE();
  HAL_GPIO_WritePin(GPIOB, GPIO_PIN_6, GPIO_PIN_SET); /* CS high: deselected */
  gpio.Pin = GPIO_PIN_6;
  gpio.Mode = GPIO_MODE_OUTPUT_PP;
  gpio.Speed = GPIO_SPEED_FREQ_HIGH;
  HAL_GPIO_Init(GPIOB, &gpio);
  gpio.Pin = GPIO_PIN_3; /* BUSY: open drain on the chip, pulled up here */
  gpio.Mode = GPIO_MODE_INPUT;
  gpio.Pull = GPIO_PULLUP;
  HAL_GPIO_Init(GPIOB, &gpio);
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

/* One byte in its own CS frame, as the chip wants it; returns the byte shifted out. */
static uint8_t xfer(uint8_t byte) {
  uint8_t answer = 0;
  HAL_GPIO_WritePin(GPIOB, GPIO_PIN_6, GPIO_PIN_RESET);
  if (HAL_SPI_TransmitReceive(&hspi1, &byte, &answer, 1, 10) != HAL_OK) Error_Handler();
  HAL_GPIO_WritePin(GPIOB, GPIO_PIN_6, GPIO_PIN_SET);
  return answer;
}

int main(void) {
  HAL_Init();
  MX_GPIO_Init();
  MX_SPI1_Init();

  xfer(0xD0); /* GetStatus: clears the UVLO flag of power-up */
  xfer(0x00);
  xfer(0x00);
  const uint8_t move[] = {0x41, 0x00, 0x0C, 0x80}; /* Move(FWD, 3200 microsteps) */
  for (unsigned i = 0; i < sizeof move; ++i) xfer(move[i]);
  const uint32_t start = HAL_GetTick();
  while (HAL_GPIO_ReadPin(GPIOB, GPIO_PIN_3) == GPIO_PIN_RESET) HAL_Delay(1); /* BUSY low: moving */

  xfer(0x21); /* GetParam(ABS_POS): three answer bytes */
  uint32_t pos = (uint32_t)xfer(0x00) << 16;
  pos |= (uint32_t)xfer(0x00) << 8;
  pos |= xfer(0x00);
  printf("at %lu after %lu ms\n", (unsigned long)pos, (unsigned long)(HAL_GetTick() - start));
  return pos == 3200 ? 0 : 1;
}
