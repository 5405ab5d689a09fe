// Shared helpers for the tests: a one-chip rig and readable conversions.
#pragma once

// AddressSanitizer, as gcc (__SANITIZE_ADDRESS__) and clang (__has_feature) say it: defines
// L6470EMU_TEST_ASAN in a sanitized build (its programs keep freed memory in quarantine and map
// terabytes of shadow memory: no peak or ulimit -v says anything there).
#if defined(__SANITIZE_ADDRESS__)
#define L6470EMU_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define L6470EMU_TEST_ASAN 1
#endif
#endif

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

/// L6470 STATUS bits (datasheet Table 34); an N suffix marks an active-low flag.
namespace status_bits {
inline constexpr std::uint16_t kHiZ = 1u << 0;
inline constexpr std::uint16_t kBusyN = 1u << 1;  ///< set = not busy
inline constexpr std::uint16_t kSwF = 1u << 2;
inline constexpr std::uint16_t kSwEvn = 1u << 3;
inline constexpr std::uint16_t kDir = 1u << 4;
inline constexpr std::uint16_t kNotPerf = 1u << 7;
inline constexpr std::uint16_t kWrongCmd = 1u << 8;
inline constexpr std::uint16_t kUvloN = 1u << 9;
inline constexpr std::uint16_t kThWrnN = 1u << 10;
inline constexpr std::uint16_t kThSdN = 1u << 11;
inline constexpr std::uint16_t kOcdN = 1u << 12;
inline constexpr std::uint16_t kStepLossAN = 1u << 13;
inline constexpr std::uint16_t kStepLossBN = 1u << 14;
inline constexpr std::uint16_t kSckMod = 1u << 15;
/// MOT_STATUS values.
inline constexpr unsigned kStopped = 0, kAccel = 1, kDecel = 2, kConst = 3;
/// MOT_STATUS field of a STATUS value.
inline unsigned mot(std::uint16_t status) { return (status >> 5) & 3u; }
}  // namespace status_bits

/// How long a Move of `n_step` microsteps takes on an L6470 in its power-up state (BUSY low from
/// the decoded command to its release): the profile's own duration, from the model itself.
Tick move_profile_ticks(bool forward, std::uint32_t n_step);

/// One L6470 behind its own chip-select, with a host talking to it.
struct OneChip {
  Chain chain{1};
  ChainHost host{chain};
  Chip& chip() { return chain.chip(0); }
};

}  // namespace l6470emu::test
