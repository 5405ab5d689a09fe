// The phase drive of a chip: the levels of coil A and coil B as the bridges apply them while
// EL_POS walks the microstep sine, scaled by the KVAL (or TVAL) of the motion phase in force. A
// view of the chip's registers for pictures (the report page); the emulator's own electrical
// model is core/drive_model.hpp. Not modelled: BEMF compensation, the automatic full-step mode
// above FS_SPD, the PWM itself.
#pragma once

#include <cstdint>

#include "core/chip.hpp"

namespace l6470emu {

/// The two phase drive levels, in tenths of a percent of the bridges' full scale (supply
/// voltage in voltage mode, the TVAL range in current mode), signed: -1000..1000.
struct PhaseDrive {
  std::int16_t coil_a = 0;
  std::int16_t coil_b = 0;
  friend bool operator==(const PhaseDrive&, const PhaseDrive&) = default;
};

/// Coil A and B of the sine generator at electrical position `el_pos` (EL_POS, 9 bits: 512 per
/// electrical period, 128 per full step) for an amplitude of `permille` (0..1000) of full scale.
/// Full steps sit at odd multiples of 45° (datasheet Figure 6: both phases at sin(π/4) of the
/// peak), so EL_POS 0 is 45°: coil A = sin(θ), coil B = cos(θ), θ = 2π·(EL_POS + 64)/512.
/// Which winding the datasheet calls A is our reading (UNCONFIRMED); the patterns are not.
PhaseDrive phase_levels(std::uint16_t el_pos, unsigned permille);

/// What `chip`'s bridges apply now: 0 on both coils in high impedance; otherwise
/// phase_levels(EL_POS) at the amplitude of KVAL_HOLD/RUN/ACC/DEC (of 256) or TVAL_* (of 128)
/// as MOT_STATUS selects it (stopped: HOLD, constant speed: RUN, accelerating: ACC,
/// decelerating: DEC).
PhaseDrive phase_drive(const Chip& chip);

}  // namespace l6470emu
