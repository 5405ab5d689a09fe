// The STATUS register as conditions and latches, and its encoding into a
// variant's 16-bit layout. Which events set which flag is decided by Chip.
#pragma once

#include <cstdint>
#include <string>

#include "core/motion.hpp"
#include "core/status_layout.hpp"

namespace l6470emu {

/// Die temperature as the chip classifies it (TH_STATUS encoding on the gate-driver parts).
enum class Thermal : std::uint8_t { normal = 0, warning = 1, bridge_shutdown = 2, device_shutdown = 3 };

/// Alarm conditions in positive logic (true = the alarm is on). Used twice:
/// once for what is physically happening, once for what STATUS shows (latched).
struct AlarmFlags {
  bool uvlo = false;
  bool uvlo_adc = false;
  bool ocd = false;
  bool stall_a = false;
  bool stall_b = false;
  bool wrong_cmd = false;
  bool notperf_cmd = false;
  bool sw_evn = false;
  Thermal thermal = Thermal::normal;

  friend bool operator==(const AlarmFlags&, const AlarmFlags&) = default;
};

/// The live (unlatched) inputs of STATUS.
struct LiveStatus {
  bool hiz = true;
  bool busy = false;       ///< a command keeps BUSY low
  bool sw_closed = false;  ///< SW_F: the SW pin is low
  bool forward = false;    ///< DIR
  bool step_clock = false; ///< SCK_MOD / STCK_MOD
  MotStatus mot = MotStatus::stopped;
};

/// Encodes the latched flags of STATUS in `layout` (the live fields read as 0).
std::uint16_t encode_latched(const StatusLayout& layout, const AlarmFlags& latched);

/// Encodes the live fields of STATUS in `layout` (the latched flags read as 0).
std::uint16_t encode_live(const StatusLayout& layout, const LiveStatus& live);

/// Encodes STATUS in `layout`.
inline std::uint16_t encode_status(const StatusLayout& layout, const AlarmFlags& latched, const LiveStatus& live) {
  return static_cast<std::uint16_t>(encode_latched(layout, latched) | encode_live(layout, live));
}

/// Names of the notable STATUS conditions, e.g. "HiZ UVLO" (for dumps and logs).
std::string describe_status(const StatusLayout& layout, std::uint16_t status);

}  // namespace l6470emu
