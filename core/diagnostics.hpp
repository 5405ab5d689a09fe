// Diagnostics: host mistakes the chip notices (unknown opcodes, refused commands).
// The chip reports them to an optional sink; it never stops because of them.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "core/tick.hpp"

namespace l6470emu {

/// What kind of mistake a diagnostic reports.
enum class DiagnosticKind : std::uint8_t {
  wrong_cmd,    ///< byte that is no command, or a register address that does not exist
  notperf_cmd,  ///< command refused in the current state
  ignored,      ///< a byte or pin change the chip ignored (standby, ...)
};

/// More about a wrong_cmd or notperf_cmd diagnostic.
enum class DiagnosticDetail : std::uint8_t {
  none,
  read_only_write,    ///< SetParam of a read-only register
  refused_running,    ///< a command or a WS write refused while the motor runs
  refused_busy,       ///< a positioning command refused while BUSY
  refused_bridges_on, ///< a WH write, or ResetDevice on some parts, refused while the bridges are enabled
  refused_fault_hiz,  ///< a motion command refused while a fault holds the bridges in HiZ
};

/// One diagnostic, stamped with the tick at which the chip noticed it.
struct Diagnostic {
  Tick tick = 0;
  DiagnosticKind kind = DiagnosticKind::wrong_cmd;
  std::string message;
  DiagnosticDetail detail = DiagnosticDetail::none;
};

/// Receives diagnostics; may be empty.
using DiagnosticSink = std::function<void(const Diagnostic&)>;

}  // namespace l6470emu
