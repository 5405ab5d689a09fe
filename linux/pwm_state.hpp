// The kernel's PWM sysfs class (Documentation/ABI/testing/sysfs-class-pwm, drivers/pwm/sysfs.c)
// as plain data: the attributes of a pwmchip and of an exported channel, a channel's settings,
// and what a write to an attribute makes of them, with the kernel's errors. No board here: the
// DeviceBoard turns a channel's settings into a pulse train on a chip's STCK
// (device_board_pwm.cpp).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace l6470emu {

/// An attribute file: npwm, export and unexport of a pwmchip; the others of a channel pwmK.
enum class PwmAttr : std::uint8_t { npwm, export_channel, unexport_channel, period, duty_cycle, enable, polarity };

/// The attribute named `name` ("period", "export", ...) among a chip's (`of_channel` false) or a
/// channel's files; nullopt for any other name.
std::optional<PwmAttr> pwm_attr_named(std::string_view name, bool of_channel);
/// The file name of `attr`.
const char* pwm_attr_name(PwmAttr attr);
/// Whether the file can be read (npwm and the channel's files; export and unexport are 0200).
bool pwm_attr_readable(PwmAttr attr);
/// Whether the file can be written (all but npwm, which is 0444).
bool pwm_attr_writable(PwmAttr attr);

/// A channel's state as its sysfs files show it (struct pwm_state): nanoseconds.
struct PwmSettings {
  std::uint64_t period_ns = 0;
  std::uint64_t duty_ns = 0;
  bool enabled = false;
  bool inversed = false;
};

/// The kernel's kstrtou64(text, 0): an optional '+', decimal, 0x hex or 0 octal, one optional
/// trailing newline. Returns 0 (value in `out`), -EINVAL or -ERANGE.
long parse_kernel_u64(std::string_view text, std::uint64_t& out);

/// The settings after writing `text` to channel attribute `attr` (period, duty_cycle, enable or
/// polarity) of a channel that has `now`: 0 and `out`, or the kernel's -errno (-EINVAL for a bad
/// number, an enable other than 0/1, a polarity other than normal/inversed, a period of 0, a
/// duty_cycle longer than the period; -ERANGE for a number over 64 bits).
long pwm_settings_after(const PwmSettings& now, PwmAttr attr, std::string_view text, PwmSettings& out);

/// What a read of channel attribute `attr` returns ("1000000\n", "normal\n").
std::string pwm_attr_text(const PwmSettings& s, PwmAttr attr);

}  // namespace l6470emu
