/* An STM32Cube HAL program for two daisy-chained L6470s, written the way CubeMX lays one out:
 * SystemClock_Config, MX_GPIO_Init (CS on PA4, FLAG on PA10 as a falling-edge EXTI line, BUSY
 * on PB5, STBY_RST on PB10), MX_SPI1_Init (mode 3: CPOL high, second edge; MSB first; APB/32),
 * the EXTI handler in the program, HAL_GPIO_EXTI_Callback, and a driver on
 * HAL_SPI_TransmitReceive; then HAL_SPI_Transmit/Receive with CS by TogglePin, and the handle
 * re-initialised LSB first and in mode 0, whose bits come back as silicon gives them. It checks
 * itself and prints PASS. */
#include <stdio.h>
#include <stdlib.h>

#include "stm32f4xx_hal.h"

#define CHIPS 2
#define CS_PORT GPIOA
#define CS_PIN GPIO_PIN_4
#define FLAG_PIN GPIO_PIN_10
#define BUSY_PORT GPIOB
#define BUSY_PIN GPIO_PIN_5
#define RESET_PORT GPIOB
#define RESET_PIN GPIO_PIN_10

SPI_HandleTypeDef hspi1;
static volatile int flag_events = 0;
static volatile uint32_t flag_tick = 0;
static int failures = 0;

static void check(int ok, const char* what) {
  printf("%s %s\n", ok ? "ok  " : "FAIL", what);
  if (!ok) ++failures;
}

void Error_Handler(void) {
  printf("FAIL Error_Handler\n");
  exit(1);
}

static void SystemClock_Config(void) {
  RCC_OscInitTypeDef osc = {0};
  RCC_ClkInitTypeDef clk = {0};
  __HAL_RCC_PWR_CLK_ENABLE();
  __HAL_PWR_VOLTAGESCALING_CONFIG(PWR_REGULATOR_VOLTAGE_SCALE2);
  osc.OscillatorType = RCC_OSCILLATORTYPE_HSI;
  osc.HSIState = RCC_HSI_ON;
  osc.HSICalibrationValue = RCC_HSICALIBRATION_DEFAULT;
  osc.PLL.PLLState = RCC_PLL_ON;
  osc.PLL.PLLSource = RCC_PLLSOURCE_HSI;
  osc.PLL.PLLM = 16;
  osc.PLL.PLLN = 336;
  osc.PLL.PLLP = RCC_PLLP_DIV4;
  osc.PLL.PLLQ = 7;
  if (HAL_RCC_OscConfig(&osc) != HAL_OK) Error_Handler();
  clk.ClockType = RCC_CLOCKTYPE_HCLK | RCC_CLOCKTYPE_SYSCLK | RCC_CLOCKTYPE_PCLK1 | RCC_CLOCKTYPE_PCLK2;
  clk.SYSCLKSource = RCC_SYSCLKSOURCE_PLLCLK;
  clk.AHBCLKDivider = RCC_SYSCLK_DIV1;
  clk.APB1CLKDivider = RCC_HCLK_DIV2;
  clk.APB2CLKDivider = RCC_HCLK_DIV1;
  if (HAL_RCC_ClockConfig(&clk, FLASH_LATENCY_2) != HAL_OK) Error_Handler();
}

static void MX_GPIO_Init(void) {
  GPIO_InitTypeDef gpio = {0};
  __HAL_RCC_GPIOA_CLK_ENABLE();
  __HAL_RCC_GPIOB_CLK_ENABLE();
  HAL_GPIO_WritePin(CS_PORT, CS_PIN, GPIO_PIN_SET);
  HAL_GPIO_WritePin(RESET_PORT, RESET_PIN, GPIO_PIN_RESET);
  gpio.Pin = CS_PIN;
  gpio.Mode = GPIO_MODE_OUTPUT_PP;
  gpio.Pull = GPIO_NOPULL;
  gpio.Speed = GPIO_SPEED_FREQ_HIGH;
  HAL_GPIO_Init(CS_PORT, &gpio);
  gpio.Pin = RESET_PIN;
  HAL_GPIO_Init(RESET_PORT, &gpio);
  gpio.Pin = BUSY_PIN;
  gpio.Mode = GPIO_MODE_INPUT;
  gpio.Pull = GPIO_PULLUP;
  HAL_GPIO_Init(BUSY_PORT, &gpio);
  gpio.Pin = FLAG_PIN;
  gpio.Mode = GPIO_MODE_IT_FALLING;
  gpio.Pull = GPIO_PULLUP;
  HAL_GPIO_Init(GPIOA, &gpio);
  HAL_NVIC_SetPriority(EXTI15_10_IRQn, 0, 0);
  HAL_NVIC_EnableIRQ(EXTI15_10_IRQn);
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
  hspi1.Init.TIMode = SPI_TIMODE_DISABLE;
  hspi1.Init.CRCCalculation = SPI_CRCCALCULATION_DISABLE;
  hspi1.Init.CRCPolynomial = 10;
  if (HAL_SPI_Init(&hspi1) != HAL_OK) Error_Handler();
}

/* stm32f4xx_it.c */
void EXTI15_10_IRQHandler(void) { HAL_GPIO_EXTI_IRQHandler(FLAG_PIN); }

void HAL_GPIO_EXTI_Callback(uint16_t pin) {
  if (pin == FLAG_PIN) {
    ++flag_events;
    flag_tick = HAL_GetTick();
  }
}

/* One frame: byte k to chip k (chip 0 drives MISO). */
static void frame(const uint8_t* tx, uint8_t* rx) {
  uint8_t sink[CHIPS];
  HAL_GPIO_WritePin(CS_PORT, CS_PIN, GPIO_PIN_RESET);
  if (HAL_SPI_TransmitReceive(&hspi1, tx, rx ? rx : sink, CHIPS, 10) != HAL_OK) Error_Handler();
  HAL_GPIO_WritePin(CS_PORT, CS_PIN, GPIO_PIN_SET);
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

static void wait_busy(void) {
  while (HAL_GPIO_ReadPin(BUSY_PORT, BUSY_PIN) == GPIO_PIN_RESET) HAL_Delay(1);
}

int main(void) {
  HAL_Init();
  SystemClock_Config();
  MX_GPIO_Init();
  MX_SPI1_Init();

  HAL_Delay(1);
  HAL_GPIO_WritePin(RESET_PORT, RESET_PIN, GPIO_PIN_SET); /* out of reset */
  HAL_Delay(1);
  check(HAL_GPIO_ReadPin(GPIOA, FLAG_PIN) == GPIO_PIN_RESET, "FLAG low after the reset (UVLO latched)");
  check(flag_events == 0, "no falling edge: FLAG was low from power-up on");
  for (int k = 0; k < CHIPS; ++k) {
    const uint32_t config = command(k, 0x38, 0, 0, 2);
    char line[80];
    snprintf(line, sizeof line, "chip %d CONFIG 0x%04X", k, (unsigned)config);
    check(config == 0x2E88, line);
    command(k, 0xD0, 0, 0, 2); /* GetStatus: UVLO cleared */
  }
  check(HAL_GPIO_ReadPin(GPIOA, FLAG_PIN) == GPIO_PIN_SET, "FLAG released");

  const uint32_t start = HAL_GetTick();
  command(1, 0x41, 3, 6400, 0); /* Move(FWD, 6400) on chip 1 */
  check(HAL_GPIO_ReadPin(BUSY_PORT, BUSY_PIN) == GPIO_PIN_RESET, "BUSY low while chip 1 moves");
  wait_busy();
  const uint32_t took = HAL_GetTick() - start;
  printf("chip 1's move took %u ms\n", (unsigned)took);
  check(took >= 300 && took <= 330, "6400 microsteps at the power-up profile");
  check(command(1, 0x21, 0, 0, 3) == 6400, "chip 1 ABS_POS 6400");
  check(command(0, 0x21, 0, 0, 3) == 0, "chip 0 did not move");

  const uint32_t t0 = HAL_GetTick();
  HAL_Delay(5);
  check(HAL_GetTick() - t0 == 6, "HAL_Delay(5) waits 5 ms and the HAL's extra tick");

  uint8_t bad[CHIPS] = {0xF8, 0x00}; /* an opcode chip 0 does not know: WRONG_CMD, FLAG falls */
  frame(bad, NULL);
  check(flag_events == 1, "the EXTI callback ran once for FLAG's falling edge");
  check(flag_tick == HAL_GetTick(), "at the time of the frame");
  check((command(0, 0xD0, 0, 0, 2) & 0x0100) != 0, "chip 0 reports WRONG_CMD");

  __disable_irq();
  frame(bad, NULL);
  HAL_Delay(2);
  check(flag_events == 1, "no callback while interrupts are disabled");
  __enable_irq();
  check(flag_events == 2, "__enable_irq delivers it");

  uint8_t word[2] = {0x38, 0x00};
  check(HAL_SPI_Transmit(&hspi1, word, 0, 10) == HAL_ERROR, "a transfer of no data is an error");
  SPI_HandleTypeDef never_initialised = {0};
  never_initialised.Instance = SPI1;
  check(HAL_SPI_Transmit(&never_initialised, word, 1, 10) == HAL_BUSY, "a handle never initialised is busy");

  /* HAL_SPI_Transmit and HAL_SPI_Receive, CS by TogglePin: SetParam(MAX_SPEED) of both chips,
   * then GetParam(MAX_SPEED) and its answer received (Receive sends its buffer: NOPs). */
  const uint8_t set[3][CHIPS] = {{0x07, 0x07}, {0x01, 0x02}, {0x23, 0x45}}, get[CHIPS] = {0x27, 0x27};
  for (int i = 0; i < 3; ++i) {
    HAL_GPIO_TogglePin(CS_PORT, CS_PIN);
    check(HAL_SPI_Transmit(&hspi1, set[i], CHIPS, 10) == HAL_OK, "HAL_SPI_Transmit");
    HAL_GPIO_TogglePin(CS_PORT, CS_PIN);
  }
  check(HAL_GPIO_ReadPin(CS_PORT, CS_PIN) == GPIO_PIN_SET, "TogglePin twice a frame leaves CS high");
  HAL_GPIO_TogglePin(CS_PORT, CS_PIN);
  HAL_SPI_Transmit(&hspi1, get, CHIPS, 10);
  HAL_GPIO_TogglePin(CS_PORT, CS_PIN);
  uint8_t hi[CHIPS] = {0}, lo[CHIPS] = {0};
  HAL_GPIO_TogglePin(CS_PORT, CS_PIN);
  check(HAL_SPI_Receive(&hspi1, hi, CHIPS, 10) == HAL_OK, "HAL_SPI_Receive");
  HAL_GPIO_TogglePin(CS_PORT, CS_PIN);
  HAL_GPIO_TogglePin(CS_PORT, CS_PIN);
  HAL_SPI_Receive(&hspi1, lo, CHIPS, 10);
  HAL_GPIO_TogglePin(CS_PORT, CS_PIN);
  char line[96];
  snprintf(line, sizeof line, "Transmit/Receive: MAX_SPEED 0x%03X and 0x%03X", hi[0] << 8 | lo[0], hi[1] << 8 | lo[1]);
  check((hi[0] << 8 | lo[0]) == 0x123 && (hi[1] << 8 | lo[1]) == 0x245, line);

  /* FirstBit LSB: each byte goes out and comes in bit-reversed, so a driver that reverses what
   * it sends reads the chip's answer reversed: CONFIG 0x2E88 as 0x74 0x11. */
  hspi1.Init.FirstBit = SPI_FIRSTBIT_LSB;
  if (HAL_SPI_Init(&hspi1) != HAL_OK) Error_Handler();
  const uint8_t get_config_lsb[CHIPS] = {0x1C, 0x1C}; /* 0x38 with its bits reversed */
  const uint8_t nop[CHIPS] = {0, 0};
  uint8_t a[CHIPS], b[CHIPS];
  frame(get_config_lsb, NULL);
  HAL_GPIO_WritePin(CS_PORT, CS_PIN, GPIO_PIN_RESET);
  HAL_SPI_TransmitReceive(&hspi1, nop, a, CHIPS, 10);
  HAL_GPIO_WritePin(CS_PORT, CS_PIN, GPIO_PIN_SET);
  HAL_GPIO_WritePin(CS_PORT, CS_PIN, GPIO_PIN_RESET);
  HAL_SPI_TransmitReceive(&hspi1, nop, b, CHIPS, 10);
  HAL_GPIO_WritePin(CS_PORT, CS_PIN, GPIO_PIN_SET);
  snprintf(line, sizeof line, "FirstBit LSB: CONFIG bytes 0x%02X 0x%02X and 0x%02X 0x%02X", a[0], b[0], a[1], b[1]);
  check(a[0] == 0x74 && b[0] == 0x11 && a[1] == 0x74 && b[1] == 0x11, line);

  /* CLKPolarity LOW, CLKPhase 1EDGE (mode 0), MSB first: the first rising edge comes before a
   * chip's first falling edge has put bit 7 of its answer on SDO, so each chip sends its stale SDO
   * latch for it (docs/spi-interface.md); chip 1's answer passes through chip 0 with that bit
   * already lost. CONFIG 0x2E88 reads 0x2E08 from both. */
  hspi1.Init.FirstBit = SPI_FIRSTBIT_MSB;
  hspi1.Init.CLKPolarity = SPI_POLARITY_LOW;
  hspi1.Init.CLKPhase = SPI_PHASE_1EDGE;
  if (HAL_SPI_Init(&hspi1) != HAL_OK) Error_Handler();
  const uint32_t config0 = command(0, 0x38, 0, 0, 2), config1 = command(1, 0x38, 0, 0, 2);
  snprintf(line, sizeof line, "mode 0: chip 0 reads CONFIG as 0x%04X, chip 1 as 0x%04X", (unsigned)config0,
           (unsigned)config1);
  check(config0 == 0x2E08 && config1 == 0x2E08, line);

  printf("%s\n", failures == 0 ? "PASS" : "FAIL");
  return failures == 0 ? 0 : 1;
}
