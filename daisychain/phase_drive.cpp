// phase_drive: EL_POS and the amplitude register of the motion phase, read from the chip.
#include "daisychain/phase_drive.hpp"

#include <cmath>
#include <numbers>

namespace l6470emu {

PhaseDrive phase_levels(std::uint16_t el_pos, unsigned permille) {
  const double theta = 2.0 * std::numbers::pi * static_cast<double>((el_pos & 0x1FFu) + 64u) / 512.0;
  const double amplitude = static_cast<double>(permille > 1000 ? 1000 : permille);
  return {static_cast<std::int16_t>(std::lround(amplitude * std::sin(theta))),
          static_cast<std::int16_t>(std::lround(amplitude * std::cos(theta)))};
}

PhaseDrive phase_drive(const Chip& chip) {
  const MotionState& m = chip.motion();
  if (m.hiz) return {};
  const Variant& table = chip.registers();
  const bool current_mode = table.has(Reg::TVAL_RUN);
  static constexpr Reg kVoltage[] = {Reg::KVAL_HOLD, Reg::KVAL_ACC, Reg::KVAL_DEC, Reg::KVAL_RUN};
  static constexpr Reg kCurrent[] = {Reg::TVAL_HOLD, Reg::TVAL_ACC, Reg::TVAL_DEC, Reg::TVAL_RUN};
  const auto phase = static_cast<std::size_t>(mot_status(m, chip.profile()));  // 0 stopped, 1 acc, 2 dec, 3 const
  const Reg level = current_mode ? kCurrent[phase] : kVoltage[phase];
  const RegisterInfo* r = table.find(level);
  if (r == nullptr) return {};
  const std::uint32_t value = chip.peek(level) & r->mask();
  const double full = static_cast<double>(r->mask()) + 1.0;  // KVAL: 256, TVAL: 128
  const auto permille = static_cast<unsigned>(std::lround(1000.0 * static_cast<double>(value) / full));
  return phase_levels(m.el_pos, permille);
}

}  // namespace l6470emu
