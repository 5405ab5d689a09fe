// Shared helpers for the tests: a one-chip rig and readable conversions.
#pragma once

#include <cstdint>

#include "daisychain/chain.hpp"
#include "daisychain/host.hpp"

namespace l6470emu::test {

/// Speed register values from step/s (test inputs only; the model never sees floats).
std::uint32_t spd_from_steps_per_s(double steps_per_s);       ///< Run/GoUntil SPD, 2^-28 step/tick
std::uint32_t max_speed_from_steps_per_s(double steps_per_s); ///< MAX_SPEED, 2^-18 step/tick
std::uint32_t min_speed_from_steps_per_s(double steps_per_s); ///< MIN_SPEED, 2^-24 step/tick
std::uint32_t acc_from_steps_per_s2(double steps_per_s2);     ///< ACC/DEC, 2^-40 step/tick²
double steps_per_s_from_speed(std::uint32_t speed_reg);       ///< SPEED register → step/s

/// One L6470 behind its own chip-select, with a host talking to it.
struct OneChip {
  Chain chain{1};
  ChainHost host{chain};
  Chip& chip() { return chain.chip(0); }
};

}  // namespace l6470emu::test
