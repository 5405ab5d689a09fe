// What the power stage can do at a given speed: phase voltage from KVAL and the BEMF
// compensation (or the TVAL current target), the motor's back-EMF and impedance, the phase
// current, the torque it gives, the torque the load needs, and the chip's current comparators.
// Integer arithmetic only; the equations are in docs/chip-model.md, "The mechanical world".
#pragma once

#include <array>
#include <cstdint>

#include "core/axis_spec.hpp"

namespace l6470emu {

/// How the chip sets the phase current.
enum class DriveMode : std::uint8_t {
  voltage,        ///< L6470, L6480, powerSTEP01 with CM_VM = 0: KVAL sets the voltage amplitude
  current_ma,     ///< L6472, L6474: TVAL is a current, 31.25 mA·(n+1)
  current_sense,  ///< L6482, powerSTEP01 with CM_VM = 1: TVAL is a sense voltage, 7.8 mV·(n+1)
};

/// What a comparator threshold register measures.
enum class Comparator : std::uint8_t {
  none,          ///< the variant has no such detection (L6472/L6482 stall)
  current_31mA,  ///< L6470 STALL_TH: phase current above 31.25 mA·(n+1)
  current_375mA, ///< L6470/L6472 OCD_TH: phase current above 375 mA·(n+1)
  vds_31mV,      ///< gate-driver parts: MOSFET V_DS = I·R_DS(on) above 31.25 mV·(n+1)
};

/// Which KVAL/TVAL and which BEMF slope apply (the motion phase, as MOT_STATUS says).
enum class DrivePhase : std::uint8_t { hold = 0, run = 1, acc = 2, dec = 3 };

/// The chip's registers that shape the drive, read by Chip whenever they change.
struct DriveInputs {
  DriveMode mode = DriveMode::voltage;
  std::array<std::uint8_t, 4> level{};  ///< KVAL or TVAL by DrivePhase: hold, run, acc, dec
  std::uint8_t st_slp = 0;
  std::uint8_t fn_slp_acc = 0;
  std::uint8_t fn_slp_dec = 0;
  std::uint16_t int_speed = 0;          ///< INT_SPEED, 2^-24 step/tick
  std::uint8_t k_therm = 0;             ///< K_THERM: factor 1 + n/32
  Comparator stall_kind = Comparator::none;
  std::uint8_t stall_th = 0;
  Comparator ocd_kind = Comparator::none;
  std::uint8_t ocd_th = 0;
  std::uint64_t acc = 0;                ///< ACC, 2^-40 step/tick²
  std::uint64_t dec = 0;                ///< DEC, 2^-40 step/tick²
  bool infinite = false;                ///< ACC = 0xFFF: speed jumps, no inertial torque counted

  friend bool operator==(const DriveInputs&, const DriveInputs&) = default;
};

/// Speed-dependent quantities are evaluated per band of 2^-18 step/tick (the MAX_SPEED unit,
/// 15.26 step/s), at the band's lower edge.
inline constexpr unsigned kSpeedBands = 1024;
/// The band of a speed in 2^-40 step/tick.
constexpr std::uint32_t speed_band(std::uint64_t speed) {
  const std::uint64_t b = speed >> 22;
  return b >= kSpeedBands ? kSpeedBands - 1 : static_cast<std::uint32_t>(b);
}

/// The electrical state of a phase at one speed band.
struct DrivePoint {
  std::uint32_t voltage_mV = 0;      ///< phase voltage amplitude the bridge applies
  std::uint32_t emf_mV = 0;          ///< back-EMF of a rotor turning at the band's speed
  std::uint32_t impedance_mohm = 0;  ///< |Z| = sqrt(R² + (ω_e·L)²)
  std::uint32_t sync_mA = 0;         ///< phase current while the rotor follows
  std::uint32_t blocked_mA = 0;      ///< phase current while the rotor stands still (no back-EMF)
  std::uint32_t torque_uNm = 0;      ///< torque the following rotor can give
};

/// The drive at speed band `band` in `phase`.
DrivePoint drive_point(const AxisSpec& axis, const DriveInputs& in, DrivePhase phase, std::uint32_t band);

/// Torque the motor must give to follow the profile in `phase` going `forward`, µN·m:
/// |±J·α + friction + load force|.
std::uint64_t required_torque_uNm(const AxisSpec& axis, const DriveInputs& in, DrivePhase phase, bool forward);

/// Whether a comparator of `kind` set to `threshold` trips at phase current `current_mA`.
bool comparator_trips(Comparator kind, std::uint8_t threshold, std::uint32_t current_mA, std::uint32_t rds_on_mohm);

/// Integer square root (floor).
std::uint64_t isqrt(std::uint64_t v);

}  // namespace l6470emu
