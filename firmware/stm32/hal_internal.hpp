// What the STM32 HAL front's files share (not installed): the TIM part's hooks that hal.cpp's
// GPIO and NVIC calls reach.
#pragma once

#include <cstdint>

/// HAL_GPIO_Init gave port pin `port_pin` (port × 16 + pin) alternate function `alternate`:
/// true when that makes it a timer's output (hal_tim.cpp then drives it from the timer).
bool l6470emu_tim_gpio_af(unsigned port_pin, std::uint32_t alternate);
/// HAL_NVIC_EnableIRQ / DisableIRQ of `irqn`: true when it is a timer's vector (handled).
bool l6470emu_tim_nvic(int irqn, bool enable);
