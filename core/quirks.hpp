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

/// All switchable quirks of one chip.
struct Quirks {
  ReadOnlyWrite read_only_write = ReadOnlyWrite::wrong_cmd_at_command_byte;
  BemfWriteCondition bemf_write = BemfWriteCondition::when_hiz;
};

}  // namespace l6470emu
