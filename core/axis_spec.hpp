// The description of the mechanics behind one chip: motor, load, supply, travel limits
// with hard stops and the switches wired to SW. Plain integers; no behaviour here.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/tick.hpp"

namespace l6470emu {

/// Positions on an axis are counted in 1/128 full step (EL_POS resolution); 512 is one
/// electrical cycle (four full steps).
inline constexpr std::int64_t kAxisUnitsPerStep = 128;

/// A switch at a position of the axis, wired to the chip's SW pin.
struct SwitchSpec {
  std::string name = "home";     ///< for messages and `ctl axis`
  std::int64_t position = 0;     ///< where it actuates, 1/128 step (true position)
  /// true: actuated at and above `position` (a limit at the high end); false: at and below it.
  bool above = false;
  bool normally_closed = false;  ///< contact closed (SW low) while NOT actuated
  /// Hysteresis, 1/128 step: once actuated it releases only `hysteresis` beyond `position`.
  std::int64_t hysteresis = 0;
  /// Contact bounce: after each change the contact reverts `bounce_count` times, each
  /// reversal and each return `bounce_ticks` apart (deterministic). 0 = clean edges.
  std::uint32_t bounce_count = 0;
  Tick bounce_ticks = 0;

  friend bool operator==(const SwitchSpec&, const SwitchSpec&) = default;
};

/// The motor and its load. Defaults: a common NEMA-17 (200 steps/rev, 0.44 N·m at 1.7 A,
/// 1.5 Ω, 2.8 mH, 57 g·cm² rotor) on a 12 V supply, no load.
struct MotorSpec {
  std::uint32_t steps_per_rev = 200;          ///< full steps per revolution
  std::uint32_t holding_torque_uNm = 440'000; ///< at the rated current, µN·m
  std::uint32_t rated_current_mA = 1'700;     ///< phase current of the holding torque, mA
  std::uint32_t rotor_inertia_g_mm2 = 5'700;  ///< g·mm² (57 g·cm²)
  std::uint32_t phase_resistance_mohm = 1'500;///< mΩ per phase
  std::uint32_t phase_inductance_uH = 2'800;  ///< µH per phase

  friend bool operator==(const MotorSpec&, const MotorSpec&) = default;
};

struct LoadSpec {
  std::uint32_t inertia_g_mm2 = 0;  ///< load inertia seen at the motor shaft, g·mm²
  std::uint32_t friction_uNm = 0;   ///< Coulomb friction torque, µN·m, opposes motion
  /// Constant torque at the shaft, µN·m; positive pushes toward negative positions
  /// (e.g. gravity on an axis that goes up forward), negative toward positive ones.
  std::int32_t force_uNm = 0;

  friend bool operator==(const LoadSpec&, const LoadSpec&) = default;
};

/// Electrical surroundings of the chip that the registers do not say.
struct SupplySpec {
  std::uint32_t supply_mV = 12'000;  ///< motor supply VS, mV
  /// Gate-driver parts (L6480, L6482, powerSTEP01): on-resistance of the bridge MOSFETs whose
  /// V_DS the stall and overcurrent comparators watch, mΩ.
  std::uint32_t rds_on_mohm = 16;
  /// Current-mode gate-driver parts (L6482, powerSTEP01 with CM_VM = 1): sense resistor that
  /// turns TVAL (a sense voltage) into a phase current, mΩ.
  std::uint32_t sense_mohm = 200;

  friend bool operator==(const SupplySpec&, const SupplySpec&) = default;
};

/// Everything the axis behind one chip is made of.
struct AxisSpec {
  MotorSpec motor;
  LoadSpec load;
  SupplySpec supply;
  /// Hard stops, 1/128 step (true position); without one the axis is unbounded that way.
  bool has_lower_stop = false;
  std::int64_t lower_stop = 0;
  bool has_upper_stop = false;
  std::int64_t upper_stop = 0;
  std::int64_t start_position = 0;  ///< the rotor's true position when the axis is attached
  /// A stalled rotor pulls back in once the commanded speed is at or below this (step/s, whole
  /// numbers); at 0 it pulls in only when the commanded motion stops.
  std::uint32_t pull_in_speed_steps_per_s = 0;
  std::vector<SwitchSpec> switches;

  friend bool operator==(const AxisSpec&, const AxisSpec&) = default;
};

}  // namespace l6470emu
