// The GPIO character device's argument rules (drivers/gpio/gpiolib-cdev.c, Linux 6.1) for
// both uAPIs: v1 handle/event flags are turned into v2 line flags, and requests and
// configurations are checked with the kernel's error codes. Pure functions, no OS calls.
#pragma once

#include <linux/gpio.h>

#include <cstdint>

namespace l6470emu {

/// Every flag a v2 line configuration may carry.
inline constexpr std::uint64_t kV2ValidFlags =
    GPIO_V2_LINE_FLAG_ACTIVE_LOW | GPIO_V2_LINE_FLAG_INPUT | GPIO_V2_LINE_FLAG_OUTPUT |
    GPIO_V2_LINE_FLAG_EDGE_RISING | GPIO_V2_LINE_FLAG_EDGE_FALLING | GPIO_V2_LINE_FLAG_OPEN_DRAIN |
    GPIO_V2_LINE_FLAG_OPEN_SOURCE | GPIO_V2_LINE_FLAG_BIAS_PULL_UP | GPIO_V2_LINE_FLAG_BIAS_PULL_DOWN |
    GPIO_V2_LINE_FLAG_BIAS_DISABLED | GPIO_V2_LINE_FLAG_EVENT_CLOCK_REALTIME | GPIO_V2_LINE_FLAG_EVENT_CLOCK_HTE;
inline constexpr std::uint64_t kV2EdgeFlags = GPIO_V2_LINE_FLAG_EDGE_RISING | GPIO_V2_LINE_FLAG_EDGE_FALLING;

/// gpio_v2_line_flags_validate: 0 or -EINVAL.
int validate_v2_flags(std::uint64_t flags);
/// gpio_v2_line_config_validate for `num_lines` lines: 0 or -EINVAL.
int validate_v2_config(const gpio_v2_line_config& config, unsigned num_lines);
/// The flags of line `index` of a request (a FLAGS attribute overrides config.flags).
std::uint64_t v2_config_flags(const gpio_v2_line_config& config, unsigned index);
/// The debounce period of line `index` in microseconds (0 = none).
std::uint32_t v2_config_debounce_us(const gpio_v2_line_config& config, unsigned index);
/// Whether line `index` has an output value in the config, and which.
bool v2_config_output_value(const gpio_v2_line_config& config, unsigned index, bool& value);

/// linehandle_validate_flags: 0 or -EINVAL.
int validate_v1_handle_flags(std::uint32_t flags);
/// v1 handle flags as v2 line flags.
std::uint64_t v1_handle_flags_to_v2(std::uint32_t flags);
/// v1 event request checks (lineevent_create): 0 or -EINVAL.
int validate_v1_event_flags(std::uint32_t handleflags, std::uint32_t eventflags);
/// v1 event request as v2 line flags (input, edges, bias, active low).
std::uint64_t v1_event_flags_to_v2(std::uint32_t handleflags, std::uint32_t eventflags);
/// v2 line info flags as v1 GPIOLINE_FLAG_* bits.
std::uint32_t v2_info_flags_to_v1(std::uint64_t flags);

}  // namespace l6470emu
