// Switchable choices where the sources disagree (spec "CONFLICT" rows).
// The defaults are the recommended readings; docs/quirks.md explains each one.
#pragma once

#include <cstdint>

namespace l6470emu {

/// SetParam aimed at a read-only register (SPEED, ADC_OUT, STATUS).
enum class ReadOnlyWrite : std::uint8_t {
  /// SetParam section of the datasheet: WRONG_CMD at the command byte, as for an
  /// unknown opcode, so the value bytes that follow are decoded as commands. (default)
  wrong_cmd_at_command_byte,
  /// Per-register sections: the value bytes are consumed, then NOTPERF_CMD rises.
  notperf_after_value,
};

/// Write condition of INT_SPEED, ST_SLP, FN_SLP_ACC, FN_SLP_DEC and CONFIG.
enum class BemfWriteCondition : std::uint8_t {
  when_hiz,      ///< register table: WH, only with the bridges disabled (default)
  when_stopped,  ///< register text: refused only while the motor runs (like WS)
};

/// Which STATUS bit carries which stall flag on the L6480 and powerSTEP01.
enum class StallBitOrder : std::uint8_t {
  a_on_14,  ///< STALL_A bit 14, STALL_B bit 15: ST's powerSTEP01 and cSPIN code (default)
  a_on_15,  ///< STALL_A bit 15, STALL_B bit 14: two third-party libraries
};

/// ResetDevice while the bridges are enabled.
enum class ResetDeviceWhenEnabled : std::uint8_t {
  variant_default,  ///< refused on the powerSTEP01 (community report), performed elsewhere (default)
  performed,        ///< always reset, as the datasheets describe ResetDevice
  refused,          ///< always refused with NOTPERF_CMD / CMD_ERROR
};

/// All switchable quirks of one chip.
struct Quirks {
  ReadOnlyWrite read_only_write = ReadOnlyWrite::wrong_cmd_at_command_byte;
  BemfWriteCondition bemf_write = BemfWriteCondition::when_hiz;
  StallBitOrder stall_bits = StallBitOrder::a_on_14;
  ResetDeviceWhenEnabled reset_device = ResetDeviceWhenEnabled::variant_default;
};

}  // namespace l6470emu
