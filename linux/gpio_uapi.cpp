// v1/v2 GPIO uAPI flag rules, after drivers/gpio/gpiolib-cdev.c.
#include "linux/gpio_uapi.hpp"

#include <cerrno>

namespace l6470emu {
namespace {

constexpr std::uint64_t kBiasFlags =
    GPIO_V2_LINE_FLAG_BIAS_PULL_UP | GPIO_V2_LINE_FLAG_BIAS_PULL_DOWN | GPIO_V2_LINE_FLAG_BIAS_DISABLED;
constexpr std::uint64_t kDriveFlags = GPIO_V2_LINE_FLAG_OPEN_DRAIN | GPIO_V2_LINE_FLAG_OPEN_SOURCE;
constexpr std::uint64_t kDirectionFlags = GPIO_V2_LINE_FLAG_INPUT | GPIO_V2_LINE_FLAG_OUTPUT;
constexpr std::uint32_t kV1ValidHandleFlags =
    GPIOHANDLE_REQUEST_INPUT | GPIOHANDLE_REQUEST_OUTPUT | GPIOHANDLE_REQUEST_ACTIVE_LOW |
    GPIOHANDLE_REQUEST_OPEN_DRAIN | GPIOHANDLE_REQUEST_OPEN_SOURCE | GPIOHANDLE_REQUEST_BIAS_PULL_UP |
    GPIOHANDLE_REQUEST_BIAS_PULL_DOWN | GPIOHANDLE_REQUEST_BIAS_DISABLE;

bool any_nonzero(const std::uint32_t* p, unsigned n) {
  for (unsigned i = 0; i < n; ++i)
    if (p[i]) return true;
  return false;
}

}  // namespace

int validate_v2_flags(std::uint64_t flags) {
  if (flags & ~kV2ValidFlags) return -EINVAL;
  if ((flags & GPIO_V2_LINE_FLAG_INPUT) && (flags & GPIO_V2_LINE_FLAG_OUTPUT)) return -EINVAL;
  if ((flags & kV2EdgeFlags) && !(flags & GPIO_V2_LINE_FLAG_INPUT)) return -EINVAL;
  if ((flags & GPIO_V2_LINE_FLAG_OPEN_DRAIN) && (flags & GPIO_V2_LINE_FLAG_OPEN_SOURCE)) return -EINVAL;
  if ((flags & kDriveFlags) && !(flags & GPIO_V2_LINE_FLAG_OUTPUT)) return -EINVAL;
  if ((flags & kBiasFlags) && !(flags & kDirectionFlags)) return -EINVAL;
  const std::uint64_t bias = flags & kBiasFlags;
  if (bias & (bias - 1)) return -EINVAL;  // more than one bias flag
  return 0;
}

std::uint64_t v2_config_flags(const gpio_v2_line_config& config, unsigned index) {
  for (unsigned i = 0; i < config.num_attrs && i < GPIO_V2_LINE_NUM_ATTRS_MAX; ++i) {
    const auto& a = config.attrs[i];
    if ((a.mask >> index) & 1u && a.attr.id == GPIO_V2_LINE_ATTR_ID_FLAGS) return a.attr.flags;
  }
  return config.flags;
}

std::uint32_t v2_config_debounce_us(const gpio_v2_line_config& config, unsigned index) {
  for (unsigned i = 0; i < config.num_attrs && i < GPIO_V2_LINE_NUM_ATTRS_MAX; ++i) {
    const auto& a = config.attrs[i];
    if ((a.mask >> index) & 1u && a.attr.id == GPIO_V2_LINE_ATTR_ID_DEBOUNCE) return a.attr.debounce_period_us;
  }
  return 0;
}

bool v2_config_output_value(const gpio_v2_line_config& config, unsigned index, bool& value) {
  for (unsigned i = 0; i < config.num_attrs && i < GPIO_V2_LINE_NUM_ATTRS_MAX; ++i) {
    const auto& a = config.attrs[i];
    if ((a.mask >> index) & 1u && a.attr.id == GPIO_V2_LINE_ATTR_ID_OUTPUT_VALUES) {
      value = (a.attr.values >> index) & 1u;
      return true;
    }
  }
  return false;
}

int validate_v2_config(const gpio_v2_line_config& config, unsigned num_lines) {
  if (config.num_attrs > GPIO_V2_LINE_NUM_ATTRS_MAX) return -EINVAL;
  if (any_nonzero(config.padding, sizeof config.padding / sizeof config.padding[0])) return -EINVAL;
  for (unsigned i = 0; i < num_lines; ++i) {
    const std::uint64_t flags = v2_config_flags(config, i);
    if (const int r = validate_v2_flags(flags)) return r;
    if (v2_config_debounce_us(config, i) && !(flags & GPIO_V2_LINE_FLAG_INPUT)) return -EINVAL;
  }
  return 0;
}

int validate_v1_handle_flags(std::uint32_t flags) {
  if (flags & ~kV1ValidHandleFlags) return -EINVAL;
  if ((flags & GPIOHANDLE_REQUEST_INPUT) && (flags & GPIOHANDLE_REQUEST_OUTPUT)) return -EINVAL;
  if ((flags & GPIOHANDLE_REQUEST_OPEN_DRAIN) && (flags & GPIOHANDLE_REQUEST_OPEN_SOURCE)) return -EINVAL;
  const std::uint32_t bias =
      flags & (GPIOHANDLE_REQUEST_BIAS_PULL_UP | GPIOHANDLE_REQUEST_BIAS_PULL_DOWN | GPIOHANDLE_REQUEST_BIAS_DISABLE);
  if (bias && !(flags & (GPIOHANDLE_REQUEST_INPUT | GPIOHANDLE_REQUEST_OUTPUT))) return -EINVAL;
  if (bias & (bias - 1)) return -EINVAL;
  return 0;
}

std::uint64_t v1_handle_flags_to_v2(std::uint32_t flags) {
  std::uint64_t f = 0;
  if (flags & GPIOHANDLE_REQUEST_INPUT) f |= GPIO_V2_LINE_FLAG_INPUT;
  if (flags & GPIOHANDLE_REQUEST_OUTPUT) f |= GPIO_V2_LINE_FLAG_OUTPUT;
  if (flags & GPIOHANDLE_REQUEST_ACTIVE_LOW) f |= GPIO_V2_LINE_FLAG_ACTIVE_LOW;
  if (flags & GPIOHANDLE_REQUEST_OPEN_DRAIN) f |= GPIO_V2_LINE_FLAG_OPEN_DRAIN;
  if (flags & GPIOHANDLE_REQUEST_OPEN_SOURCE) f |= GPIO_V2_LINE_FLAG_OPEN_SOURCE;
  if (flags & GPIOHANDLE_REQUEST_BIAS_PULL_UP) f |= GPIO_V2_LINE_FLAG_BIAS_PULL_UP;
  if (flags & GPIOHANDLE_REQUEST_BIAS_PULL_DOWN) f |= GPIO_V2_LINE_FLAG_BIAS_PULL_DOWN;
  if (flags & GPIOHANDLE_REQUEST_BIAS_DISABLE) f |= GPIO_V2_LINE_FLAG_BIAS_DISABLED;
  return f;
}

int validate_v1_event_flags(std::uint32_t handleflags, std::uint32_t eventflags) {
  if (eventflags & ~std::uint32_t{GPIOEVENT_REQUEST_BOTH_EDGES}) return -EINVAL;
  if (handleflags & ~kV1ValidHandleFlags) return -EINVAL;
  if (handleflags & (GPIOHANDLE_REQUEST_OUTPUT | GPIOHANDLE_REQUEST_OPEN_DRAIN | GPIOHANDLE_REQUEST_OPEN_SOURCE))
    return -EINVAL;
  const std::uint32_t bias = handleflags & (GPIOHANDLE_REQUEST_BIAS_PULL_UP | GPIOHANDLE_REQUEST_BIAS_PULL_DOWN |
                                            GPIOHANDLE_REQUEST_BIAS_DISABLE);
  if (bias & (bias - 1)) return -EINVAL;
  return 0;
}

std::uint64_t v1_event_flags_to_v2(std::uint32_t handleflags, std::uint32_t eventflags) {
  std::uint64_t f = v1_handle_flags_to_v2(handleflags) | GPIO_V2_LINE_FLAG_INPUT;
  if (eventflags & GPIOEVENT_REQUEST_RISING_EDGE) f |= GPIO_V2_LINE_FLAG_EDGE_RISING;
  if (eventflags & GPIOEVENT_REQUEST_FALLING_EDGE) f |= GPIO_V2_LINE_FLAG_EDGE_FALLING;
  return f;
}

std::uint32_t v2_info_flags_to_v1(std::uint64_t flags) {
  std::uint32_t f = 0;
  if (flags & GPIO_V2_LINE_FLAG_USED) f |= GPIOLINE_FLAG_KERNEL;
  if (flags & GPIO_V2_LINE_FLAG_OUTPUT) f |= GPIOLINE_FLAG_IS_OUT;
  if (flags & GPIO_V2_LINE_FLAG_ACTIVE_LOW) f |= GPIOLINE_FLAG_ACTIVE_LOW;
  if (flags & GPIO_V2_LINE_FLAG_OPEN_DRAIN) f |= GPIOLINE_FLAG_OPEN_DRAIN;
  if (flags & GPIO_V2_LINE_FLAG_OPEN_SOURCE) f |= GPIOLINE_FLAG_OPEN_SOURCE;
  if (flags & GPIO_V2_LINE_FLAG_BIAS_PULL_UP) f |= GPIOLINE_FLAG_BIAS_PULL_UP;
  if (flags & GPIO_V2_LINE_FLAG_BIAS_PULL_DOWN) f |= GPIOLINE_FLAG_BIAS_PULL_DOWN;
  if (flags & GPIO_V2_LINE_FLAG_BIAS_DISABLED) f |= GPIOLINE_FLAG_BIAS_DISABLE;
  return f;
}

}  // namespace l6470emu
