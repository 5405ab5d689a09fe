// The drive equations (docs/chip-model.md, "The mechanical world"), in integers. Speeds of
// band b are b·15625/1024 step/s; 2π is taken as 710/113.
#include "core/drive_model.hpp"

#include <algorithm>

namespace l6470emu {
namespace {

using u128 = unsigned __int128;

constexpr std::uint64_t kBandNum = 15625;  // step/s of band b = b·15625/1024
constexpr std::uint64_t kBandDen = 1024;
constexpr std::uint64_t kTwoPiNum = 710;   // 2π ≈ 710/113
constexpr std::uint64_t kTwoPiDen = 113;

std::uint32_t clamp32(u128 v) { return v > 0xFFFF'FFFFu ? 0xFFFF'FFFFu : static_cast<std::uint32_t>(v); }

}  // namespace

std::uint64_t isqrt(std::uint64_t v) {
  if (v < 2) return v;
  std::uint64_t x = v, y = (x + 1) / 2;
  while (y < x) {
    x = y;
    y = (x + v / x) / 2;
  }
  return x;
}

DrivePoint drive_point(const AxisSpec& axis, const DriveInputs& in, DrivePhase phase, std::uint32_t band) {
  const MotorSpec& m = axis.motor;
  DrivePoint d;
  const u128 b = phase == DrivePhase::hold ? 0 : band;
  const std::uint64_t spr = std::max<std::uint32_t>(m.steps_per_rev, 4);
  const std::uint64_t rated = std::max<std::uint32_t>(m.rated_current_mA, 1);
  // Back-EMF: k_e·ω with k_e = k_t = holding torque / rated current (SI), ω = step/s·2π/spr.
  d.emf_mV = clamp32(u128{m.holding_torque_uNm} * b * kBandNum * kTwoPiNum / (u128{rated} * kBandDen * kTwoPiDen * spr));
  // Reactance ω_e·L with ω_e = step/s·2π/4 (an electrical cycle is four full steps).
  const u128 x_mohm = b * kBandNum * kTwoPiNum * m.phase_inductance_uH / (u128{kBandDen} * kTwoPiDen * 4 * 1000);
  const std::uint64_t r = std::max<std::uint32_t>(m.phase_resistance_mohm, 1);
  const u128 x = std::min<u128>(x_mohm, 0xFFFF'FFFFu);
  d.impedance_mohm = clamp32(isqrt(static_cast<std::uint64_t>(u128{r} * r + x * x)));
  const std::uint64_t z = std::max<std::uint32_t>(d.impedance_mohm, 1);
  const std::uint64_t vs = axis.supply.supply_mV;
  const std::uint8_t level = in.level[static_cast<std::size_t>(phase)];
  if (in.mode == DriveMode::voltage) {
    // KVAL_X + BEMF compensation, in 2^-24 of VS/256: slopes are 2^-16 VS per step/s.
    const u128 sps_q = b * kBandNum * 64;           // step/s · 65536
    const u128 int_q = u128{in.int_speed} * kBandNum;  // INT_SPEED (2^-24 step/tick) in step/s · 65536
    const std::uint8_t fn = phase == DrivePhase::dec ? in.fn_slp_dec : in.fn_slp_acc;
    u128 k = u128{level} << 24;
    if (phase != DrivePhase::hold) k += u128{in.st_slp} * std::min(sps_q, int_q) + u128{fn} * (sps_q > int_q ? sps_q - int_q : 0);
    k = k * (32 + in.k_therm) / 32;
    k = std::min<u128>(k, u128{255} << 24);
    d.voltage_mV = clamp32(u128{vs} * k >> 32);
    const std::uint64_t v = d.voltage_mV;
    d.sync_mA = v > d.emf_mV ? clamp32(u128{v - d.emf_mV} * 1000 / z) : 0;
    d.blocked_mA = clamp32(u128{v} * 1000 / z);
  } else {
    // Current mode: the chip regulates to TVAL as far as the full supply allows.
    const std::uint64_t target = in.mode == DriveMode::current_ma
                                     ? (std::uint64_t{level} + 1) * 125 / 4
                                     : (std::uint64_t{level} + 1) * 78 * 100 / std::max<std::uint32_t>(axis.supply.sense_mohm, 1);
    d.voltage_mV = static_cast<std::uint32_t>(vs);
    const std::uint64_t can_sync = vs > d.emf_mV ? (vs - d.emf_mV) * 1000 / z : 0;
    d.sync_mA = clamp32(std::min(target, can_sync));
    d.blocked_mA = clamp32(std::min(target, vs * 1000 / z));
  }
  // Torque k_t·I, no more than the holding torque (saturation).
  d.torque_uNm = clamp32(std::min<u128>(m.holding_torque_uNm, u128{m.holding_torque_uNm} * d.sync_mA / rated));
  return d;
}

std::uint64_t required_torque_uNm(const AxisSpec& axis, const DriveInputs& in, DrivePhase phase, bool forward) {
  const std::uint64_t spr = std::max<std::uint32_t>(axis.motor.steps_per_rev, 4);
  std::int64_t inertial = 0;
  if (!in.infinite && (phase == DrivePhase::acc || phase == DrivePhase::dec)) {
    // J·α: α = ACC·(4e6)²/2^40 step/s² · 2π/spr rad/s²; J in g·mm² is 1e-9 kg·m².
    const u128 j = u128{axis.motor.rotor_inertia_g_mm2} + axis.load.inertia_g_mm2;
    const std::uint64_t a = phase == DrivePhase::acc ? in.acc : in.dec;
    const u128 t = j * a * 16'000'000'000'000ull / (u128{1} << 40) * kTwoPiNum / (kTwoPiDen * spr * 1000);
    inertial = static_cast<std::int64_t>(std::min<u128>(t, u128{1} << 40));
    if (phase == DrivePhase::dec) inertial = -inertial;
  }
  const std::int64_t friction = phase == DrivePhase::hold ? 0 : axis.load.friction_uNm;
  const std::int64_t load = forward ? axis.load.force_uNm : -std::int64_t{axis.load.force_uNm};
  const std::int64_t t = inertial + friction + load;
  return static_cast<std::uint64_t>(t < 0 ? -t : t);
}

bool comparator_trips(Comparator kind, std::uint8_t threshold, std::uint32_t current_mA, std::uint32_t rds_on_mohm) {
  const std::uint64_t i = current_mA, n = std::uint64_t{threshold} + 1;
  switch (kind) {
    case Comparator::none: return false;
    case Comparator::current_31mA: return i * 4 > 125 * n;
    case Comparator::current_375mA: return i > 375 * n;
    case Comparator::vds_31mV: return i * rds_on_mohm * 4 > 125'000 * n;
  }
  return false;
}

}  // namespace l6470emu
