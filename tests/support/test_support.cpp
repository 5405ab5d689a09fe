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

namespace l6470emu::test {

Tick move_profile_ticks(bool forward, std::uint32_t n_step) {
  Chain c(1);
  ChainHost h(c, 0);
  h.move(0, forward, n_step);
  const Tick start = c.now();
  while (!c.chip(0).busy_sync_pin()) c.advance_to(c.next_event_tick());
  return c.now() - start;
}

}  // namespace l6470emu::test
