/* An STM32Cube HAL program with no SPI peripheral: two daisy-chained L6470s bit-banged on
 * GPIOA (PA4 CS, PA5 SCK, PA7 MOSI, PA6 MISO) with HAL_GPIO_WritePin, HAL_GPIO_TogglePin and
 * HAL_GPIO_ReadPin, shaped as SPI mode 3. It reads CONFIG of both chips, moves them, waits on
 * GetStatus's BUSY bit and reads ABS_POS back; it checks itself and prints PASS. */
#include <stdio.h>
#include <stdlib.h>

#include "stm32f4xx_hal.h"

#define CHIPS 2
#define CS_PIN GPIO_PIN_4
#define SCK_PIN GPIO_PIN_5
#define MISO_PIN GPIO_PIN_6
#define MOSI_PIN GPIO_PIN_7

static int failures = 0;

static void check(int ok, const char* what, long value) {
  printf("%s %s: %ld\n", ok ? "ok  " : "FAIL", what, value);
  if (!ok) ++failures;
}

static void MX_GPIO_Init(void) {
  GPIO_InitTypeDef gpio = {0};
  __HAL_RCC_GPIOA_CLK_ENABLE();
  HAL_GPIO_WritePin(GPIOA, CS_PIN | SCK_PIN, GPIO_PIN_SET); /* deselected, clock idle high */
  gpio.Pin = CS_PIN | SCK_PIN | MOSI_PIN;
  gpio.Mode = GPIO_MODE_OUTPUT_PP;
  gpio.Pull = GPIO_NOPULL;
  gpio.Speed = GPIO_SPEED_FREQ_VERY_HIGH;
  HAL_GPIO_Init(GPIOA, &gpio);
  gpio.Pin = MISO_PIN;
  gpio.Mode = GPIO_MODE_INPUT;
  HAL_GPIO_Init(GPIOA, &gpio);
}

/* One byte, MSB first: the clock toggled low, MOSI set, toggled high, MISO read. */
static uint8_t transfer(uint8_t out) {
  uint8_t in = 0;
  for (int bit = 7; bit >= 0; --bit) {
    HAL_GPIO_TogglePin(GPIOA, SCK_PIN);
    HAL_GPIO_WritePin(GPIOA, MOSI_PIN, (out >> bit) & 1 ? GPIO_PIN_SET : GPIO_PIN_RESET);
    HAL_GPIO_TogglePin(GPIOA, SCK_PIN);
    in = (uint8_t)(in << 1 | (HAL_GPIO_ReadPin(GPIOA, MISO_PIN) == GPIO_PIN_SET));
  }
  return in;
}

/* One frame: byte k to chip k (chip 0 drives MISO). */
static void frame(const uint8_t* tx, uint8_t* rx) {
  HAL_GPIO_WritePin(GPIOA, CS_PIN, GPIO_PIN_RESET);
  for (int k = 0; k < CHIPS; ++k) {
    const uint8_t in = transfer(tx[k]);
    if (rx) rx[k] = in;
  }
  HAL_GPIO_WritePin(GPIOA, CS_PIN, GPIO_PIN_SET);
}

static uint32_t command(int chip, uint8_t opcode, int args, uint32_t value, int answer) {
  uint8_t tx[CHIPS] = {0}, rx[CHIPS];
  uint32_t result = 0;
  tx[chip] = opcode;
  frame(tx, NULL);
  for (int i = args - 1; i >= 0; --i) {
    tx[chip] = (uint8_t)(value >> (8 * i));
    frame(tx, NULL);
  }
  tx[chip] = 0;
  for (int i = 0; i < answer; ++i) {
    frame(tx, rx);
    result = result << 8 | rx[chip];
  }
  return result;
}

static int busy(int chip) { return (command(chip, 0xD0, 0, 0, 2) & 0x0002) == 0; } /* STATUS BUSY, active low */

int main(void) {
  HAL_Init();
  MX_GPIO_Init();
  for (int k = 0; k < CHIPS; ++k) check(command(k, 0x38, 0, 0, 2) == 0x2E88, "CONFIG", (long)command(k, 0x38, 0, 0, 2));
  command(0, 0x41, 3, 1600, 0); /* Move FWD 1600 */
  command(1, 0x40, 3, 640, 0);  /* Move REV 640 */
  const uint32_t start = HAL_GetTick();
  while ((busy(0) || busy(1)) && HAL_GetTick() - start < 10000) HAL_Delay(10);
  for (int k = 0; k < CHIPS; ++k) {
    long pos = (long)command(k, 0x21, 0, 0, 3);
    if (pos & 0x200000) pos -= 0x400000;
    check(pos == (k == 0 ? 1600 : -640), "ABS_POS", pos);
  }
  printf("%s\n", failures == 0 ? "PASS" : "FAIL");
  return failures == 0 ? 0 : 1;
}
