/* stm32l0xx.h: the one STM32 HAL header of l6470emu's firmware front (stm32_hal.h). */
#include "stm32_hal.h"
