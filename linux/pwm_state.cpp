// The kernel's PWM sysfs attributes and their writes (drivers/pwm/sysfs.c, pwm_apply_might_sleep).
#include "linux/pwm_state.hpp"

#include <errno.h>
#include <limits>

namespace l6470emu {
namespace {

struct AttrName {
  PwmAttr attr;
  const char* name;
  bool of_channel;
};

constexpr AttrName kAttrs[] = {
    {PwmAttr::npwm, "npwm", false},          {PwmAttr::export_channel, "export", false},
    {PwmAttr::unexport_channel, "unexport", false}, {PwmAttr::period, "period", true},
    {PwmAttr::duty_cycle, "duty_cycle", true}, {PwmAttr::enable, "enable", true},
    {PwmAttr::polarity, "polarity", true},
};

// sysfs_streq: equal but for one trailing newline on either side.
bool sysfs_streq(std::string_view a, std::string_view b) {
  if (!a.empty() && a.back() == '\n') a.remove_suffix(1);
  return a == b;
}

}  // namespace

std::optional<PwmAttr> pwm_attr_named(std::string_view name, bool of_channel) {
  for (const AttrName& a : kAttrs)
    if (a.of_channel == of_channel && name == a.name) return a.attr;
  return std::nullopt;
}

const char* pwm_attr_name(PwmAttr attr) {
  for (const AttrName& a : kAttrs)
    if (a.attr == attr) return a.name;
  return "?";
}

bool pwm_attr_readable(PwmAttr attr) { return attr != PwmAttr::export_channel && attr != PwmAttr::unexport_channel; }
bool pwm_attr_writable(PwmAttr attr) { return attr != PwmAttr::npwm; }

long parse_kernel_u64(std::string_view s, std::uint64_t& out) {
  if (!s.empty() && s.back() == '\n') s.remove_suffix(1);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  unsigned base = 10;
  if (s.size() >= 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    base = 16;
    s.remove_prefix(2);
  } else if (s.size() >= 2 && s[0] == '0') {
    base = 8;
    s.remove_prefix(1);
  }
  if (s.empty()) return -EINVAL;
  std::uint64_t v = 0;
  for (char c : s) {
    unsigned d;
    if (c >= '0' && c <= '9')
      d = static_cast<unsigned>(c - '0');
    else if (c >= 'a' && c <= 'f')
      d = static_cast<unsigned>(c - 'a' + 10);
    else if (c >= 'A' && c <= 'F')
      d = static_cast<unsigned>(c - 'A' + 10);
    else
      return -EINVAL;
    if (d >= base) return -EINVAL;
    if (v > (std::numeric_limits<std::uint64_t>::max() - d) / base) return -ERANGE;
    v = v * base + d;
  }
  out = v;
  return 0;
}

long pwm_settings_after(const PwmSettings& now, PwmAttr attr, std::string_view text, PwmSettings& out) {
  PwmSettings next = now;
  std::uint64_t v = 0;
  switch (attr) {
    case PwmAttr::period:
    case PwmAttr::duty_cycle:
      if (const long r = parse_kernel_u64(text, v); r < 0) return r;
      (attr == PwmAttr::period ? next.period_ns : next.duty_ns) = v;
      break;
    case PwmAttr::enable: {
      // kstrtoint: a signed number; the kernel then takes 0 and 1 only.
      std::string_view t = text;
      const bool negative = !t.empty() && t.front() == '-';
      if (negative) t.remove_prefix(1);
      if (const long r = parse_kernel_u64(t, v); r < 0) return r;
      if (v > static_cast<std::uint64_t>(std::numeric_limits<int>::max())) return -ERANGE;
      if (negative || v > 1) return -EINVAL;
      next.enabled = v == 1;
      break;
    }
    case PwmAttr::polarity:
      if (sysfs_streq(text, "normal"))
        next.inversed = false;
      else if (sysfs_streq(text, "inversed"))
        next.inversed = true;
      else
        return -EINVAL;
      break;
    default:
      return -EINVAL;
  }
  // pwm_apply_might_sleep: a state without a period, or with more duty than period, is refused.
  if (next.period_ns == 0 || next.duty_ns > next.period_ns) return -EINVAL;
  out = next;
  return 0;
}

std::string pwm_attr_text(const PwmSettings& s, PwmAttr attr) {
  switch (attr) {
    case PwmAttr::period:
      return std::to_string(s.period_ns) + "\n";
    case PwmAttr::duty_cycle:
      return std::to_string(s.duty_ns) + "\n";
    case PwmAttr::enable:
      return s.enabled ? "1\n" : "0\n";
    case PwmAttr::polarity:
      return s.inversed ? "inversed\n" : "normal\n";
    default:
      return {};
  }
}

}  // namespace l6470emu
