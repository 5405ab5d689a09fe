/* The STM32Cube HAL on the desktop, as far as drivers of these chips use it (l6470emu's firmware
 * front, docs/firmware.md): GPIO with EXTI interrupts, blocking (and completing-at-once _IT/_DMA)
 * SPI honouring CLKPolarity, CLKPhase, FirstBit, DataSize and BaudRatePrescaler, HAL_Delay and
 * HAL_GetTick in virtual time, NVIC enables, PRIMASK, and the clock set-up a CubeMX main() calls
 * (accepted, no effect), timers with PWM outputs and their callbacks (stm32_hal_tim.h). One
 * header for every family: stm32f4xx_hal.h and the others include it. No registers
 * (GPIOA->ODR, SPI1->DR), UART, ADC or DMA streams are modelled. */
#ifndef L6470EMU_STM32_HAL_H
#define L6470EMU_STM32_HAL_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define L6470EMU_FIRMWARE 1

/* ---- CMSIS and HAL basics ---------------------------------------------------------------- */
#define __IO volatile
#define __I volatile const
#define __O volatile
#ifndef __weak
#define __weak __attribute__((weak))
#endif
#ifndef __STATIC_INLINE
#define __STATIC_INLINE static inline
#endif
#ifndef __ALIGN_BEGIN
#define __ALIGN_BEGIN
#define __ALIGN_END
#endif
#define __NOP() ((void)0)
#define __DSB() ((void)0)
#define __ISB() ((void)0)
#define __WFI() ((void)0)
#define UNUSED(X) (void)(X)
#define assert_param(expr) ((void)0)
#define HAL_MAX_DELAY 0xFFFFFFFFU
#define HAL_IS_BIT_SET(REG, BIT) (((REG) & (BIT)) == (BIT))
#define HAL_IS_BIT_CLR(REG, BIT) (((REG) & (BIT)) == 0U)

typedef enum { HAL_OK = 0x00U, HAL_ERROR = 0x01U, HAL_BUSY = 0x02U, HAL_TIMEOUT = 0x03U } HAL_StatusTypeDef;
typedef enum { HAL_UNLOCKED = 0x00U, HAL_LOCKED = 0x01U } HAL_LockTypeDef;
typedef enum { RESET = 0U, SET = !RESET } FlagStatus, ITStatus;
typedef enum { DISABLE = 0U, ENABLE = !DISABLE } FunctionalState;
typedef enum { SUCCESS = 0U, ERROR = !SUCCESS } ErrorStatus;
typedef enum { HAL_TICK_FREQ_1KHZ = 1U, HAL_TICK_FREQ_DEFAULT = 1U } HAL_TickFreqTypeDef;

/* Interrupts off and on (PRIMASK): nothing is delivered while off; on delivers what is pending. */
void __disable_irq(void);
void __enable_irq(void);
uint32_t __get_PRIMASK(void);
void __set_PRIMASK(uint32_t priMask);

/* The core clock CubeMX code reads (HCLK); HAL_RCC_ClockConfig does not change it. */
extern uint32_t SystemCoreClock;
void SystemInit(void);
void SystemCoreClockUpdate(void);

/* ---- HAL ---------------------------------------------------------------------------------- */
/* Opens the board (L6470EMU_CHAIN, L6470EMU_CONFIG, the program's BOARD) and calls HAL_MspInit. */
HAL_StatusTypeDef HAL_Init(void);
HAL_StatusTypeDef HAL_DeInit(void);
void HAL_MspInit(void);
void HAL_MspDeInit(void);
HAL_StatusTypeDef HAL_InitTick(uint32_t TickPriority);
/* Milliseconds of virtual time since the program started. SysTick handlers never run:
 * HAL_IncTick does nothing. */
uint32_t HAL_GetTick(void);
uint32_t HAL_GetTickPrio(void);
HAL_TickFreqTypeDef HAL_GetTickFreq(void);
HAL_StatusTypeDef HAL_SetTickFreq(HAL_TickFreqTypeDef Freq);
void HAL_IncTick(void);
/* As ST's: waits until HAL_GetTick() has moved Delay + 1 ticks on (HAL_MAX_DELAY: for ever,
 * that is until the run's time limit). */
void HAL_Delay(uint32_t Delay);
void HAL_SuspendTick(void);
void HAL_ResumeTick(void);
uint32_t HAL_GetHalVersion(void);
uint32_t HAL_GetDEVID(void);
uint32_t HAL_GetREVID(void);

/* ---- GPIO --------------------------------------------------------------------------------- */
typedef struct {
  uint32_t l6470emu_port; /* 0 = A ... 10 = K */
} GPIO_TypeDef;
extern GPIO_TypeDef l6470emu_gpio_ports[11];
#define GPIOA (&l6470emu_gpio_ports[0])
#define GPIOB (&l6470emu_gpio_ports[1])
#define GPIOC (&l6470emu_gpio_ports[2])
#define GPIOD (&l6470emu_gpio_ports[3])
#define GPIOE (&l6470emu_gpio_ports[4])
#define GPIOF (&l6470emu_gpio_ports[5])
#define GPIOG (&l6470emu_gpio_ports[6])
#define GPIOH (&l6470emu_gpio_ports[7])
#define GPIOI (&l6470emu_gpio_ports[8])
#define GPIOJ (&l6470emu_gpio_ports[9])
#define GPIOK (&l6470emu_gpio_ports[10])
#define GPIO_PIN_0 ((uint16_t)0x0001U)
#define GPIO_PIN_1 ((uint16_t)0x0002U)
#define GPIO_PIN_2 ((uint16_t)0x0004U)
#define GPIO_PIN_3 ((uint16_t)0x0008U)
#define GPIO_PIN_4 ((uint16_t)0x0010U)
#define GPIO_PIN_5 ((uint16_t)0x0020U)
#define GPIO_PIN_6 ((uint16_t)0x0040U)
#define GPIO_PIN_7 ((uint16_t)0x0080U)
#define GPIO_PIN_8 ((uint16_t)0x0100U)
#define GPIO_PIN_9 ((uint16_t)0x0200U)
#define GPIO_PIN_10 ((uint16_t)0x0400U)
#define GPIO_PIN_11 ((uint16_t)0x0800U)
#define GPIO_PIN_12 ((uint16_t)0x1000U)
#define GPIO_PIN_13 ((uint16_t)0x2000U)
#define GPIO_PIN_14 ((uint16_t)0x4000U)
#define GPIO_PIN_15 ((uint16_t)0x8000U)
#define GPIO_PIN_All ((uint16_t)0xFFFFU)
#define GPIO_PIN_MASK 0x0000FFFFU

typedef enum { GPIO_PIN_RESET = 0U, GPIO_PIN_SET } GPIO_PinState;

typedef struct {
  uint32_t Pin;
  uint32_t Mode;
  uint32_t Pull;
  uint32_t Speed;
  uint32_t Alternate;
} GPIO_InitTypeDef;

#define GPIO_MODE_INPUT 0x00000000U
#define GPIO_MODE_OUTPUT_PP 0x00000001U
#define GPIO_MODE_OUTPUT_OD 0x00000011U
#define GPIO_MODE_AF_PP 0x00000002U
#define GPIO_MODE_AF_OD 0x00000012U
#define GPIO_MODE_ANALOG 0x00000003U
#define GPIO_MODE_ANALOG_ADC_CONTROL 0x0000000BU
#define GPIO_MODE_IT_RISING 0x10110000U
#define GPIO_MODE_IT_FALLING 0x10210000U
#define GPIO_MODE_IT_RISING_FALLING 0x10310000U
#define GPIO_MODE_EVT_RISING 0x10120000U
#define GPIO_MODE_EVT_FALLING 0x10220000U
#define GPIO_MODE_EVT_RISING_FALLING 0x10320000U
#define GPIO_NOPULL 0x00000000U
#define GPIO_PULLUP 0x00000001U
#define GPIO_PULLDOWN 0x00000002U
#define GPIO_SPEED_FREQ_LOW 0x00000000U
#define GPIO_SPEED_FREQ_MEDIUM 0x00000001U
#define GPIO_SPEED_FREQ_HIGH 0x00000002U
#define GPIO_SPEED_FREQ_VERY_HIGH 0x00000003U
#define GPIO_SPEED_LOW GPIO_SPEED_FREQ_LOW
#define GPIO_SPEED_MEDIUM GPIO_SPEED_FREQ_MEDIUM
#define GPIO_SPEED_HIGH GPIO_SPEED_FREQ_HIGH
#define GPIO_AF0_SPI1 0x00U
#define GPIO_AF5_SPI1 0x05U
#define GPIO_AF5_SPI2 0x05U
#define GPIO_AF5_SPI4 0x05U
#define GPIO_AF6_SPI3 0x06U
#define GPIO_AF7_SPI3 0x07U

void HAL_GPIO_Init(GPIO_TypeDef* GPIOx, GPIO_InitTypeDef* GPIO_Init);
void HAL_GPIO_DeInit(GPIO_TypeDef* GPIOx, uint32_t GPIO_Pin);
/* GPIO_PIN_SET when any pin of the mask reads high. */
GPIO_PinState HAL_GPIO_ReadPin(GPIO_TypeDef* GPIOx, uint16_t GPIO_Pin);
void HAL_GPIO_WritePin(GPIO_TypeDef* GPIOx, uint16_t GPIO_Pin, GPIO_PinState PinState);
void HAL_GPIO_TogglePin(GPIO_TypeDef* GPIOx, uint16_t GPIO_Pin);
HAL_StatusTypeDef HAL_GPIO_LockPin(GPIO_TypeDef* GPIOx, uint16_t GPIO_Pin);
/* Clears the EXTI lines of GPIO_Pin that are pending and calls HAL_GPIO_EXTI_Callback for
 * them (and the Rising/Falling callbacks newer families call instead; all three are weak and
 * empty by default). */
void HAL_GPIO_EXTI_IRQHandler(uint16_t GPIO_Pin);
void HAL_GPIO_EXTI_Callback(uint16_t GPIO_Pin);
void HAL_GPIO_EXTI_Rising_Callback(uint16_t GPIO_Pin);
void HAL_GPIO_EXTI_Falling_Callback(uint16_t GPIO_Pin);
uint32_t l6470emu_exti_pending(uint32_t lines);
void l6470emu_exti_clear(uint32_t lines);
#define __HAL_GPIO_EXTI_GET_IT(__EXTI_LINE__) l6470emu_exti_pending(__EXTI_LINE__)
#define __HAL_GPIO_EXTI_GET_FLAG(__EXTI_LINE__) l6470emu_exti_pending(__EXTI_LINE__)
#define __HAL_GPIO_EXTI_CLEAR_IT(__EXTI_LINE__) l6470emu_exti_clear(__EXTI_LINE__)
#define __HAL_GPIO_EXTI_CLEAR_FLAG(__EXTI_LINE__) l6470emu_exti_clear(__EXTI_LINE__)

/* ---- NVIC: the EXTI interrupts run only once enabled here, as on the MCU ------------------- */
typedef enum {
  NonMaskableInt_IRQn = -14,
  SysTick_IRQn = -1,
  EXTI0_IRQn = 6,
  EXTI1_IRQn = 7,
  EXTI2_IRQn = 8,
  EXTI3_IRQn = 9,
  EXTI4_IRQn = 10,
  EXTI9_5_IRQn = 23,
  TIM1_BRK_TIM9_IRQn = 24,
  TIM1_UP_TIM10_IRQn = 25,
  TIM1_TRG_COM_TIM11_IRQn = 26,
  TIM1_CC_IRQn = 27,
  TIM2_IRQn = 28,
  TIM3_IRQn = 29,
  TIM4_IRQn = 30,
  TIM5_IRQn = 50,
  SPI1_IRQn = 35,
  SPI2_IRQn = 36,
  EXTI15_10_IRQn = 40,
  SPI3_IRQn = 51,
  EXTI0_1_IRQn = 5,
  EXTI2_3_IRQn = 106,
  EXTI4_15_IRQn = 107
} IRQn_Type;
#define NVIC_PRIORITYGROUP_0 0x00000007U
#define NVIC_PRIORITYGROUP_1 0x00000006U
#define NVIC_PRIORITYGROUP_2 0x00000005U
#define NVIC_PRIORITYGROUP_3 0x00000004U
#define NVIC_PRIORITYGROUP_4 0x00000003U
void HAL_NVIC_SetPriorityGrouping(uint32_t PriorityGroup);
void HAL_NVIC_SetPriority(IRQn_Type IRQn, uint32_t PreemptPriority, uint32_t SubPriority);
void HAL_NVIC_EnableIRQ(IRQn_Type IRQn);
void HAL_NVIC_DisableIRQ(IRQn_Type IRQn);
void HAL_NVIC_SetPendingIRQ(IRQn_Type IRQn);
void HAL_NVIC_ClearPendingIRQ(IRQn_Type IRQn);
uint32_t HAL_SYSTICK_Config(uint32_t TicksNumb);
/* The EXTI interrupt handlers: the program's own (stm32xxxx_it.c) if it has them, else these
 * weak ones, which call HAL_GPIO_EXTI_IRQHandler for their lines (F0/G0/L0: EXTI0_1, EXTI2_3,
 * EXTI4_15). */
void EXTI0_IRQHandler(void);
void EXTI1_IRQHandler(void);
void EXTI2_IRQHandler(void);
void EXTI3_IRQHandler(void);
void EXTI4_IRQHandler(void);
void EXTI9_5_IRQHandler(void);
void EXTI15_10_IRQHandler(void);
void EXTI0_1_IRQHandler(void);
void EXTI2_3_IRQHandler(void);
void EXTI4_15_IRQHandler(void);

/* ---- RCC and PWR: what a CubeMX SystemClock_Config writes, accepted without effect -------- */
typedef struct {
  uint32_t PLLState, PLLSource, PLLM, PLLN, PLLP, PLLQ, PLLR, PLLMUL, PLLDIV, PREDIV, PLLRGE, PLLVCOSEL, PLLFRACN;
} RCC_PLLInitTypeDef;
typedef struct {
  uint32_t OscillatorType, HSEState, LSEState, HSIState, HSICalibrationValue, LSIState, HSI48State, MSIState,
      MSICalibrationValue, MSIClockRange, HSIDiv, HSEDiv, LSIDiv, CSIState, CSICalibrationValue, HSI14State,
      HSI14CalibrationValue;
  RCC_PLLInitTypeDef PLL;
} RCC_OscInitTypeDef;
typedef struct {
  uint32_t ClockType, SYSCLKSource, SYSCLKDivider, AHBCLKDivider, APB1CLKDivider, APB2CLKDivider, APB3CLKDivider,
      APB4CLKDivider, AHBCLK2Divider, AHBCLK4Divider;
} RCC_ClkInitTypeDef;
typedef struct {
  uint32_t PeriphClockSelection, Spi123ClockSelection, Spi1ClockSelection, Spi2ClockSelection,
      Spi3ClockSelection, Usart1ClockSelection, Usart2ClockSelection, Lpuart1ClockSelection, I2c1ClockSelection;
} RCC_PeriphCLKInitTypeDef;
#define RCC_OSCILLATORTYPE_NONE 0x00000000U
#define RCC_OSCILLATORTYPE_HSE 0x00000001U
#define RCC_OSCILLATORTYPE_HSI 0x00000002U
#define RCC_OSCILLATORTYPE_LSE 0x00000004U
#define RCC_OSCILLATORTYPE_LSI 0x00000008U
#define RCC_OSCILLATORTYPE_MSI 0x00000010U
#define RCC_OSCILLATORTYPE_HSI48 0x00000020U
#define RCC_OSCILLATORTYPE_CSI 0x00000040U
#define RCC_HSE_OFF 0x00000000U
#define RCC_HSE_ON 0x00010000U
#define RCC_HSE_BYPASS 0x00050000U
#define RCC_HSI_OFF 0x00000000U
#define RCC_HSI_ON 0x00000001U
#define RCC_HSI_DIV1 0x00000000U
#define RCC_LSE_OFF 0x00000000U
#define RCC_LSE_ON 0x00000001U
#define RCC_LSE_BYPASS 0x00000005U
#define RCC_LSI_OFF 0x00000000U
#define RCC_LSI_ON 0x00000001U
#define RCC_MSI_OFF 0x00000000U
#define RCC_MSI_ON 0x00000001U
#define RCC_HSI48_OFF 0x00000000U
#define RCC_HSI48_ON 0x00000001U
#define RCC_CSI_OFF 0x00000000U
#define RCC_CSI_ON 0x00000080U
#define RCC_HSICALIBRATION_DEFAULT 0x10U
#define RCC_MSICALIBRATION_DEFAULT 0x00U
#define RCC_CSICALIBRATION_DEFAULT 0x10U
#define RCC_MSIRANGE_0 0x00000000U
#define RCC_MSIRANGE_1 0x00000010U
#define RCC_MSIRANGE_2 0x00000020U
#define RCC_MSIRANGE_3 0x00000030U
#define RCC_MSIRANGE_4 0x00000040U
#define RCC_MSIRANGE_5 0x00000050U
#define RCC_MSIRANGE_6 0x00000060U
#define RCC_MSIRANGE_7 0x00000070U
#define RCC_MSIRANGE_8 0x00000080U
#define RCC_MSIRANGE_9 0x00000090U
#define RCC_MSIRANGE_10 0x000000A0U
#define RCC_MSIRANGE_11 0x000000B0U
#define RCC_PLL_NONE 0x00000000U
#define RCC_PLL_OFF 0x00000001U
#define RCC_PLL_ON 0x00000002U
#define RCC_PLLSOURCE_NONE 0x00000000U
#define RCC_PLLSOURCE_HSI 0x00000002U
#define RCC_PLLSOURCE_HSE 0x00400000U
#define RCC_PLLSOURCE_MSI 0x00000001U
#define RCC_PLLSOURCE_CSI 0x00000001U
#define RCC_PLLSOURCE_HSI_DIV2 0x00000000U
#define RCC_PLL1VCIRANGE_0 0x00000000U
#define RCC_PLL1VCIRANGE_1 0x00000004U
#define RCC_PLL1VCIRANGE_2 0x00000008U
#define RCC_PLL1VCIRANGE_3 0x0000000CU
#define RCC_PLL1VCOWIDE 0x00000000U
#define RCC_PLL1VCOMEDIUM 0x00000002U
#define RCC_PLLP_DIV2 0x00000002U
#define RCC_PLLP_DIV4 0x00000004U
#define RCC_PLLP_DIV6 0x00000006U
#define RCC_PLLP_DIV8 0x00000008U
#define RCC_PLLM_DIV1 0x00000001U
#define RCC_PLLM_DIV2 0x00000002U
#define RCC_PLLM_DIV3 0x00000003U
#define RCC_PLLM_DIV4 0x00000004U
#define RCC_PLLM_DIV5 0x00000005U
#define RCC_PLLM_DIV6 0x00000006U
#define RCC_PLLM_DIV7 0x00000007U
#define RCC_PLLM_DIV8 0x00000008U
#define RCC_PLLM_DIV9 0x00000009U
#define RCC_PLLM_DIV10 0x0000000AU
#define RCC_PLLM_DIV11 0x0000000BU
#define RCC_PLLM_DIV12 0x0000000CU
#define RCC_PLLM_DIV13 0x0000000DU
#define RCC_PLLM_DIV14 0x0000000EU
#define RCC_PLLM_DIV15 0x0000000FU
#define RCC_PLLM_DIV16 0x00000010U
#define RCC_PLLQ_DIV2 0x00000002U
#define RCC_PLLR_DIV2 0x00000002U
#define RCC_PLLQ_DIV3 0x00000003U
#define RCC_PLLR_DIV3 0x00000003U
#define RCC_PLLQ_DIV4 0x00000004U
#define RCC_PLLR_DIV4 0x00000004U
#define RCC_PLLQ_DIV5 0x00000005U
#define RCC_PLLR_DIV5 0x00000005U
#define RCC_PLLQ_DIV6 0x00000006U
#define RCC_PLLR_DIV6 0x00000006U
#define RCC_PLLQ_DIV7 0x00000007U
#define RCC_PLLR_DIV7 0x00000007U
#define RCC_PLLQ_DIV8 0x00000008U
#define RCC_PLLR_DIV8 0x00000008U
#define RCC_PLL_MUL2 0x00000002U
#define RCC_PLL_MUL3 0x00000003U
#define RCC_PLL_MUL4 0x00000004U
#define RCC_PLL_MUL5 0x00000005U
#define RCC_PLL_MUL6 0x00000006U
#define RCC_PLL_MUL7 0x00000007U
#define RCC_PLL_MUL8 0x00000008U
#define RCC_PLL_MUL9 0x00000009U
#define RCC_PLL_MUL10 0x0000000AU
#define RCC_PLL_MUL11 0x0000000BU
#define RCC_PLL_MUL12 0x0000000CU
#define RCC_PLL_MUL13 0x0000000DU
#define RCC_PLL_MUL14 0x0000000EU
#define RCC_PLL_MUL15 0x0000000FU
#define RCC_PLL_MUL16 0x00000010U
#define RCC_PLL_DIV2 0x00000002U
#define RCC_PLL_DIV3 0x00000003U
#define RCC_PLL_DIV4 0x00000004U
#define RCC_HSE_PREDIV_DIV1 0x00000000U
#define RCC_HSE_PREDIV_DIV2 0x00020000U
#define RCC_PREDIV_DIV1 0x00000000U
#define RCC_PREDIV_DIV2 0x00000001U
#define RCC_CLOCKTYPE_SYSCLK 0x00000001U
#define RCC_CLOCKTYPE_HCLK 0x00000002U
#define RCC_CLOCKTYPE_PCLK1 0x00000004U
#define RCC_CLOCKTYPE_PCLK2 0x00000008U
#define RCC_CLOCKTYPE_D1PCLK1 0x00000010U
#define RCC_CLOCKTYPE_D3PCLK1 0x00000020U
#define RCC_CLOCKTYPE_PCLK3 0x00000040U
#define RCC_SYSCLKSOURCE_MSI 0x00000000U
#define RCC_SYSCLKSOURCE_HSI 0x00000000U
#define RCC_SYSCLKSOURCE_HSE 0x00000001U
#define RCC_SYSCLKSOURCE_PLLCLK 0x00000002U
#define RCC_SYSCLKSOURCE_PLLRCLK 0x00000003U
#define RCC_SYSCLKSOURCE_CSI 0x00000001U
#define RCC_SYSCLK_DIV1 0x00000000U
#define RCC_SYSCLK_DIV2 0x00000080U
#define RCC_SYSCLK_DIV4 0x00000090U
#define RCC_HCLK_DIV1 0x00000000U
#define RCC_HCLK_DIV2 0x00001000U
#define RCC_HCLK_DIV4 0x00001400U
#define RCC_HCLK_DIV8 0x00001800U
#define RCC_HCLK_DIV16 0x00001C00U
#define RCC_APB1_DIV1 RCC_HCLK_DIV1
#define RCC_APB1_DIV2 RCC_HCLK_DIV2
#define RCC_APB2_DIV1 RCC_HCLK_DIV1
#define RCC_APB2_DIV2 RCC_HCLK_DIV2
#define RCC_APB3_DIV1 RCC_HCLK_DIV1
#define RCC_APB3_DIV2 RCC_HCLK_DIV2
#define RCC_APB4_DIV1 RCC_HCLK_DIV1
#define RCC_APB4_DIV2 RCC_HCLK_DIV2
#define RCC_D1PCLK1_DIV2 RCC_HCLK_DIV2
#define RCC_D2PCLK1_DIV2 RCC_HCLK_DIV2
#define RCC_D2PCLK2_DIV2 RCC_HCLK_DIV2
#define RCC_D3PCLK1_DIV2 RCC_HCLK_DIV2
#define RCC_MCODIV_1 0x00000000U
#define RCC_MCO1SOURCE_HSI 0x00000000U
#define RCC_MCO1 0x00000000U
#define FLASH_LATENCY_0 0x00000000U
#define FLASH_LATENCY_1 0x00000001U
#define FLASH_LATENCY_2 0x00000002U
#define FLASH_LATENCY_3 0x00000003U
#define FLASH_LATENCY_4 0x00000004U
#define FLASH_LATENCY_5 0x00000005U
#define FLASH_LATENCY_6 0x00000006U
#define FLASH_LATENCY_7 0x00000007U
#define FLASH_LATENCY_8 0x00000008U
#define FLASH_LATENCY_9 0x00000009U
#define FLASH_LATENCY_10 0x0000000AU
#define FLASH_LATENCY_11 0x0000000BU
#define FLASH_LATENCY_12 0x0000000CU
#define FLASH_LATENCY_13 0x0000000DU
#define FLASH_LATENCY_14 0x0000000EU
#define FLASH_LATENCY_15 0x0000000FU
#define PWR_REGULATOR_VOLTAGE_SCALE0 0x00000000U
#define PWR_REGULATOR_VOLTAGE_SCALE1 0x0000C000U
#define PWR_REGULATOR_VOLTAGE_SCALE1_BOOST 0x00000200U
#define PWR_REGULATOR_VOLTAGE_SCALE2 0x00008000U
#define PWR_REGULATOR_VOLTAGE_SCALE3 0x00004000U
#define PWR_LDO_SUPPLY 0x00000002U
#define RCC_PERIPHCLK_SPI1 0x00000001U
#define RCC_PERIPHCLK_SPI123 0x00000001U
#define RCC_SPI123CLKSOURCE_PLL 0x00000000U
#define RCC_SPI1CLKSOURCE_PLL 0x00000000U
#define RCC_SPI1CLKSOURCE_SYSCLK 0x00000000U
HAL_StatusTypeDef HAL_RCC_OscConfig(RCC_OscInitTypeDef* RCC_OscInitStruct);
HAL_StatusTypeDef HAL_RCC_ClockConfig(RCC_ClkInitTypeDef* RCC_ClkInitStruct, uint32_t FLatency);
HAL_StatusTypeDef HAL_RCCEx_PeriphCLKConfig(RCC_PeriphCLKInitTypeDef* PeriphClkInit);
void HAL_RCC_MCOConfig(uint32_t RCC_MCOx, uint32_t RCC_MCOSource, uint32_t RCC_MCODiv);
void HAL_RCC_EnableCSS(void);
/* SystemCoreClock, and the APB clock of the description's apb_clock= for both APB buses. */
uint32_t HAL_RCC_GetSysClockFreq(void);
uint32_t HAL_RCC_GetHCLKFreq(void);
uint32_t HAL_RCC_GetPCLK1Freq(void);
uint32_t HAL_RCC_GetPCLK2Freq(void);
HAL_StatusTypeDef HAL_PWREx_EnableOverDrive(void);
HAL_StatusTypeDef HAL_PWREx_ControlVoltageScaling(uint32_t VoltageScaling);
HAL_StatusTypeDef HAL_PWREx_ConfigSupply(uint32_t SupplySource);
void HAL_PWR_EnableBkUpAccess(void);
#define __HAL_PWR_VOLTAGESCALING_CONFIG(x) ((void)(x))
#define __HAL_FLASH_SET_LATENCY(x) ((void)(x))
#define __HAL_RCC_PLL_PLLM_CONFIG(x) ((void)(x))
#define __HAL_RCC_PLL_PLLSOURCE_CONFIG(x) ((void)(x))
#define __HAL_RCC_LSEDRIVE_CONFIG(x) ((void)(x))
#define RCC_LSEDRIVE_LOW 0x00000000U
#define __HAL_PWR_GET_FLAG(x) 1U
#define PWR_FLAG_VOSRDY 0x00002000U
#define __HAL_RCC_PWR_CLK_ENABLE() ((void)0)
#define __HAL_RCC_PWR_CLK_DISABLE() ((void)0)
#define __HAL_RCC_SYSCFG_CLK_ENABLE() ((void)0)
#define __HAL_RCC_SYSCFG_CLK_DISABLE() ((void)0)
#define __HAL_RCC_DMA1_CLK_ENABLE() ((void)0)
#define __HAL_RCC_DMA1_CLK_DISABLE() ((void)0)
#define __HAL_RCC_DMA2_CLK_ENABLE() ((void)0)
#define __HAL_RCC_DMA2_CLK_DISABLE() ((void)0)
#define __HAL_RCC_DMAMUX1_CLK_ENABLE() ((void)0)
#define __HAL_RCC_DMAMUX1_CLK_DISABLE() ((void)0)
#define __HAL_RCC_AFIO_CLK_ENABLE() ((void)0)
#define __HAL_RCC_AFIO_CLK_DISABLE() ((void)0)
#define __HAL_RCC_FLASH_CLK_ENABLE() ((void)0)
#define __HAL_RCC_FLASH_CLK_DISABLE() ((void)0)
#define __HAL_RCC_CRC_CLK_ENABLE() ((void)0)
#define __HAL_RCC_CRC_CLK_DISABLE() ((void)0)
#define __HAL_RCC_USART1_CLK_ENABLE() ((void)0)
#define __HAL_RCC_USART1_CLK_DISABLE() ((void)0)
#define __HAL_RCC_USART2_CLK_ENABLE() ((void)0)
#define __HAL_RCC_USART2_CLK_DISABLE() ((void)0)
#define __HAL_RCC_USART3_CLK_ENABLE() ((void)0)
#define __HAL_RCC_USART3_CLK_DISABLE() ((void)0)
#define __HAL_RCC_UART4_CLK_ENABLE() ((void)0)
#define __HAL_RCC_UART4_CLK_DISABLE() ((void)0)
#define __HAL_RCC_UART5_CLK_ENABLE() ((void)0)
#define __HAL_RCC_UART5_CLK_DISABLE() ((void)0)
#define __HAL_RCC_LPUART1_CLK_ENABLE() ((void)0)
#define __HAL_RCC_LPUART1_CLK_DISABLE() ((void)0)
#define __HAL_RCC_TIM1_CLK_ENABLE() ((void)0)
#define __HAL_RCC_TIM1_CLK_DISABLE() ((void)0)
#define __HAL_RCC_TIM2_CLK_ENABLE() ((void)0)
#define __HAL_RCC_TIM2_CLK_DISABLE() ((void)0)
#define __HAL_RCC_TIM3_CLK_ENABLE() ((void)0)
#define __HAL_RCC_TIM3_CLK_DISABLE() ((void)0)
#define __HAL_RCC_TIM4_CLK_ENABLE() ((void)0)
#define __HAL_RCC_TIM4_CLK_DISABLE() ((void)0)
#define __HAL_RCC_I2C1_CLK_ENABLE() ((void)0)
#define __HAL_RCC_I2C1_CLK_DISABLE() ((void)0)
#define __HAL_RCC_I2C2_CLK_ENABLE() ((void)0)
#define __HAL_RCC_I2C2_CLK_DISABLE() ((void)0)
#define __HAL_RCC_ADC1_CLK_ENABLE() ((void)0)
#define __HAL_RCC_ADC1_CLK_DISABLE() ((void)0)
#define __HAL_RCC_ADC12_CLK_ENABLE() ((void)0)
#define __HAL_RCC_ADC12_CLK_DISABLE() ((void)0)
#define __HAL_RCC_D2SRAM1_CLK_ENABLE() ((void)0)
#define __HAL_RCC_D2SRAM1_CLK_DISABLE() ((void)0)
#define __HAL_RCC_GPIOA_CLK_ENABLE() ((void)0)
#define __HAL_RCC_GPIOA_CLK_DISABLE() ((void)0)
#define __HAL_RCC_GPIOB_CLK_ENABLE() ((void)0)
#define __HAL_RCC_GPIOB_CLK_DISABLE() ((void)0)
#define __HAL_RCC_GPIOC_CLK_ENABLE() ((void)0)
#define __HAL_RCC_GPIOC_CLK_DISABLE() ((void)0)
#define __HAL_RCC_GPIOD_CLK_ENABLE() ((void)0)
#define __HAL_RCC_GPIOD_CLK_DISABLE() ((void)0)
#define __HAL_RCC_GPIOE_CLK_ENABLE() ((void)0)
#define __HAL_RCC_GPIOE_CLK_DISABLE() ((void)0)
#define __HAL_RCC_GPIOF_CLK_ENABLE() ((void)0)
#define __HAL_RCC_GPIOF_CLK_DISABLE() ((void)0)
#define __HAL_RCC_GPIOG_CLK_ENABLE() ((void)0)
#define __HAL_RCC_GPIOG_CLK_DISABLE() ((void)0)
#define __HAL_RCC_GPIOH_CLK_ENABLE() ((void)0)
#define __HAL_RCC_GPIOH_CLK_DISABLE() ((void)0)
#define __HAL_RCC_GPIOI_CLK_ENABLE() ((void)0)
#define __HAL_RCC_GPIOI_CLK_DISABLE() ((void)0)
#define __HAL_RCC_GPIOJ_CLK_ENABLE() ((void)0)
#define __HAL_RCC_GPIOJ_CLK_DISABLE() ((void)0)
#define __HAL_RCC_GPIOK_CLK_ENABLE() ((void)0)
#define __HAL_RCC_GPIOK_CLK_DISABLE() ((void)0)
#define __HAL_RCC_SPI1_CLK_ENABLE() ((void)0)
#define __HAL_RCC_SPI1_CLK_DISABLE() ((void)0)
#define __HAL_RCC_SPI2_CLK_ENABLE() ((void)0)
#define __HAL_RCC_SPI2_CLK_DISABLE() ((void)0)
#define __HAL_RCC_SPI3_CLK_ENABLE() ((void)0)
#define __HAL_RCC_SPI3_CLK_DISABLE() ((void)0)
#define __HAL_RCC_SPI4_CLK_ENABLE() ((void)0)
#define __HAL_RCC_SPI4_CLK_DISABLE() ((void)0)
#define __HAL_RCC_SPI5_CLK_ENABLE() ((void)0)
#define __HAL_RCC_SPI5_CLK_DISABLE() ((void)0)
#define __HAL_RCC_SPI6_CLK_ENABLE() ((void)0)
#define __HAL_RCC_SPI6_CLK_DISABLE() ((void)0)
#define __HAL_AFIO_REMAP_SWJ_NOJTAG() ((void)0)
#define __HAL_AFIO_REMAP_SWJ_DISABLE() ((void)0)

/* ---- SPI ---------------------------------------------------------------------------------- */
typedef struct {
  uint32_t l6470emu_controller; /* 0 = SPI1 ... 5 = SPI6 */
} SPI_TypeDef;
extern SPI_TypeDef l6470emu_spi_instances[6];
#define SPI1 (&l6470emu_spi_instances[0])
#define SPI2 (&l6470emu_spi_instances[1])
#define SPI3 (&l6470emu_spi_instances[2])
#define SPI4 (&l6470emu_spi_instances[3])
#define SPI5 (&l6470emu_spi_instances[4])
#define SPI6 (&l6470emu_spi_instances[5])

typedef struct {
  uint32_t Mode;
  uint32_t Direction;
  uint32_t DataSize;
  uint32_t CLKPolarity;
  uint32_t CLKPhase;
  uint32_t NSS;
  uint32_t BaudRatePrescaler;
  uint32_t FirstBit;
  uint32_t TIMode;
  uint32_t CRCCalculation;
  uint32_t CRCPolynomial;
  uint32_t CRCLength;
  uint32_t NSSPMode;
  uint32_t NSSPolarity;
  uint32_t FifoThreshold;
  uint32_t MasterKeepIOState;
} SPI_InitTypeDef;

typedef enum {
  HAL_SPI_STATE_RESET = 0x00U,
  HAL_SPI_STATE_READY = 0x01U,
  HAL_SPI_STATE_BUSY = 0x02U,
  HAL_SPI_STATE_BUSY_TX = 0x03U,
  HAL_SPI_STATE_BUSY_RX = 0x04U,
  HAL_SPI_STATE_BUSY_TX_RX = 0x05U,
  HAL_SPI_STATE_ERROR = 0x06U,
  HAL_SPI_STATE_ABORT = 0x07U
} HAL_SPI_StateTypeDef;

typedef struct __SPI_HandleTypeDef {
  SPI_TypeDef* Instance;
  SPI_InitTypeDef Init;
  const uint8_t* pTxBuffPtr;
  uint16_t TxXferSize;
  __IO uint16_t TxXferCount;
  uint8_t* pRxBuffPtr;
  uint16_t RxXferSize;
  __IO uint16_t RxXferCount;
  void* hdmatx;
  void* hdmarx;
  HAL_LockTypeDef Lock;
  __IO HAL_SPI_StateTypeDef State;
  __IO uint32_t ErrorCode;
} SPI_HandleTypeDef;

#define SPI_MODE_SLAVE 0x00000000U
#define SPI_MODE_MASTER 0x00000104U
#define SPI_DIRECTION_2LINES 0x00000000U
#define SPI_DIRECTION_2LINES_RXONLY 0x00000400U
#define SPI_DIRECTION_1LINE 0x00008000U
#define SPI_DATASIZE_8BIT 0x00000700U
#define SPI_DATASIZE_16BIT 0x00000F00U
#define SPI_POLARITY_LOW 0x00000000U
#define SPI_POLARITY_HIGH 0x00000002U
#define SPI_PHASE_1EDGE 0x00000000U
#define SPI_PHASE_2EDGE 0x00000001U
#define SPI_NSS_SOFT 0x00000200U
#define SPI_NSS_HARD_INPUT 0x00000000U
#define SPI_NSS_HARD_OUTPUT 0x00040000U
#define SPI_BAUDRATEPRESCALER_2 0x00000000U
#define SPI_BAUDRATEPRESCALER_4 0x00000008U
#define SPI_BAUDRATEPRESCALER_8 0x00000010U
#define SPI_BAUDRATEPRESCALER_16 0x00000018U
#define SPI_BAUDRATEPRESCALER_32 0x00000020U
#define SPI_BAUDRATEPRESCALER_64 0x00000028U
#define SPI_BAUDRATEPRESCALER_128 0x00000030U
#define SPI_BAUDRATEPRESCALER_256 0x00000038U
#define SPI_FIRSTBIT_MSB 0x00000000U
#define SPI_FIRSTBIT_LSB 0x00000080U
#define SPI_TIMODE_DISABLE 0x00000000U
#define SPI_TIMODE_ENABLE 0x00000010U
#define SPI_CRCCALCULATION_DISABLE 0x00000000U
#define SPI_CRCCALCULATION_ENABLE 0x00002000U
#define SPI_CRC_LENGTH_DATASIZE 0x00000000U
#define SPI_CRC_LENGTH_8BIT 0x00000001U
#define SPI_CRC_LENGTH_16BIT 0x00000002U
#define SPI_NSS_PULSE_DISABLE 0x00000000U
#define SPI_NSS_PULSE_ENABLE 0x00000008U
#define SPI_NSS_POLARITY_LOW 0x00000000U
#define SPI_FIFO_THRESHOLD_01DATA 0x00000000U
#define SPI_MASTER_KEEP_IO_STATE_DISABLE 0x00000000U
#define SPI_MASTER_KEEP_IO_STATE_ENABLE 0x00000001U
#define HAL_SPI_ERROR_NONE 0x00000000U
#define HAL_SPI_ERROR_MODF 0x00000001U
#define HAL_SPI_ERROR_CRC 0x00000002U
#define HAL_SPI_ERROR_OVR 0x00000004U
#define HAL_SPI_ERROR_FRE 0x00000008U
#define HAL_SPI_ERROR_DMA 0x00000010U
#define HAL_SPI_ERROR_FLAG 0x00000020U
#define __HAL_SPI_ENABLE(__HANDLE__) ((void)(__HANDLE__))
#define __HAL_SPI_DISABLE(__HANDLE__) ((void)(__HANDLE__))

/* The handle's Instance names the controller (SPI1 = the description's spi=SPI1, or bus 0);
 * SCK = apb_clock= / the prescaler. HAL_SPI_Init calls HAL_SPI_MspInit (weak, empty). */
HAL_StatusTypeDef HAL_SPI_Init(SPI_HandleTypeDef* hspi);
HAL_StatusTypeDef HAL_SPI_DeInit(SPI_HandleTypeDef* hspi);
void HAL_SPI_MspInit(SPI_HandleTypeDef* hspi);
void HAL_SPI_MspDeInit(SPI_HandleTypeDef* hspi);
/* Blocking: the words clock on the bus (every chain whose chip select is low) and their bus
 * time passes. HAL_BUSY before HAL_SPI_Init, HAL_ERROR for no data; HAL_TIMEOUT when the bus
 * time exceeds Timeout ms (words up to then are sent). Receive sends the buffer's own contents,
 * as ST's full-duplex master does. */
HAL_StatusTypeDef HAL_SPI_Transmit(SPI_HandleTypeDef* hspi, const uint8_t* pData, uint16_t Size, uint32_t Timeout);
HAL_StatusTypeDef HAL_SPI_Receive(SPI_HandleTypeDef* hspi, uint8_t* pData, uint16_t Size, uint32_t Timeout);
HAL_StatusTypeDef HAL_SPI_TransmitReceive(SPI_HandleTypeDef* hspi, const uint8_t* pTxData, uint8_t* pRxData,
                                          uint16_t Size, uint32_t Timeout);
/* _IT and _DMA: the transfer completes at once (its bus time passes), then its completion
 * callback runs (weak, empty by default). */
HAL_StatusTypeDef HAL_SPI_Transmit_IT(SPI_HandleTypeDef* hspi, const uint8_t* pData, uint16_t Size);
HAL_StatusTypeDef HAL_SPI_Receive_IT(SPI_HandleTypeDef* hspi, uint8_t* pData, uint16_t Size);
HAL_StatusTypeDef HAL_SPI_TransmitReceive_IT(SPI_HandleTypeDef* hspi, const uint8_t* pTxData, uint8_t* pRxData,
                                             uint16_t Size);
HAL_StatusTypeDef HAL_SPI_Transmit_DMA(SPI_HandleTypeDef* hspi, const uint8_t* pData, uint16_t Size);
HAL_StatusTypeDef HAL_SPI_Receive_DMA(SPI_HandleTypeDef* hspi, uint8_t* pData, uint16_t Size);
HAL_StatusTypeDef HAL_SPI_TransmitReceive_DMA(SPI_HandleTypeDef* hspi, const uint8_t* pTxData, uint8_t* pRxData,
                                              uint16_t Size);
void HAL_SPI_TxCpltCallback(SPI_HandleTypeDef* hspi);
void HAL_SPI_RxCpltCallback(SPI_HandleTypeDef* hspi);
void HAL_SPI_TxRxCpltCallback(SPI_HandleTypeDef* hspi);
void HAL_SPI_ErrorCallback(SPI_HandleTypeDef* hspi);
HAL_SPI_StateTypeDef HAL_SPI_GetState(SPI_HandleTypeDef* hspi);
uint32_t HAL_SPI_GetError(SPI_HandleTypeDef* hspi);

/* ---- TIM ----------------------------------------------------------------------------------- */
#include "stm32_hal_tim.h"

#ifdef __cplusplus
}
#endif

#endif /* L6470EMU_STM32_HAL_H */
