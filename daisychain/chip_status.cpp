// ChipStatus's thermal class: two flags on the L6470/L6472, a 2-bit field on the gate-driver parts.
#include "daisychain/chip_status.hpp"

namespace l6470emu {

Thermal ChipStatus::thermal() const {
  if (layout_->th_status >= 0) return static_cast<Thermal>((raw_ >> layout_->th_status) & 3u);
  if (layout_->th_sd >= 0 && !bit(layout_->th_sd)) return Thermal::device_shutdown;
  if (layout_->th_wrn >= 0 && !bit(layout_->th_wrn)) return Thermal::warning;
  return Thermal::normal;
}

}  // namespace l6470emu
