// Conversions between physical units and register values, for readable tests.
#include "support/test_support.hpp"

#include <cmath>

namespace l6470emu::test {

std::uint32_t spd_from_steps_per_s(double v) { return static_cast<std::uint32_t>(std::lround(v * 0.25e-6 * (1 << 28))); }
std::uint32_t max_speed_from_steps_per_s(double v) { return static_cast<std::uint32_t>(std::lround(v * 0.25e-6 * (1 << 18))); }
std::uint32_t min_speed_from_steps_per_s(double v) { return static_cast<std::uint32_t>(std::lround(v * 0.25e-6 * (1 << 24))); }
std::uint32_t acc_from_steps_per_s2(double a) { return static_cast<std::uint32_t>(std::lround(a * 0.0625e-12 * std::ldexp(1.0, 40))); }
double steps_per_s_from_speed(std::uint32_t s) { return s / (0.25e-6 * (1 << 28)); }

}  // namespace l6470emu::test
