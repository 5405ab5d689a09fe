// The application command set: opcode classification shared by all variants.
// Which opcodes exist for a variant is decided by its register table (SetParam/GetParam).
#pragma once

#include <cstdint>
#include <string_view>

namespace l6470emu {

/// The commands of the datasheet's command table, plus the two outcomes of a byte that is no command.
enum class Command : std::uint8_t {
  NOP, SetParam, GetParam, Run, StepClock, Move, GoTo, GoTo_DIR, GoUntil, ReleaseSW,
  GoHome, GoMark, ResetPos, ResetDevice, SoftStop, HardStop, SoftHiZ, HardHiZ, GetStatus,
  Enable,    ///< the L6474's: bridges on (HardStop's opcode, 0xB8); no other part decodes it
  Disable,   ///< the L6474's: bridges in high impedance (HardHiZ's opcode, 0xA8)
  Reserved,  ///< 0xEB / 0xF8, "RESERVED COMMAND": treated as unknown (UNCONFIRMED)
  Unknown,   ///< no such command, or a parameter address the variant lacks
};

/// Whether `c` starts (or steers) a motion: Run, StepClock, Move, GoTo, GoTo_DIR, GoUntil,
/// ReleaseSW, GoHome, GoMark.
constexpr bool is_motion_command(Command c) {
  switch (c) {
    case Command::Run: case Command::StepClock: case Command::Move: case Command::GoTo: case Command::GoTo_DIR:
    case Command::GoUntil: case Command::ReleaseSW: case Command::GoHome: case Command::GoMark:
      return true;
    default:
      return false;
  }
}

/// A decoded opcode byte.
struct Opcode {
  Command command = Command::Unknown;
  std::uint8_t arg_bytes = 0;  ///< argument bytes that follow the opcode
  std::uint8_t param = 0;      ///< PARAM field of SetParam/GetParam
  bool dir = false;            ///< DIR bit: true = forward
  bool act = false;            ///< ACT bit of GoUntil/ReleaseSW: true = copy ABS_POS to MARK
};

/// The datasheet name of a command.
constexpr std::string_view to_string(Command c) {
  constexpr std::string_view names[] = {
      "NOP", "SetParam", "GetParam", "Run", "StepClock", "Move", "GoTo", "GoTo_DIR",
      "GoUntil", "ReleaseSW", "GoHome", "GoMark", "ResetPos", "ResetDevice", "SoftStop",
      "HardStop", "SoftHiZ", "HardHiZ", "GetStatus", "Enable", "Disable", "RESERVED", "unknown"};
  return names[static_cast<unsigned>(c)];
}

/// What an opcode means on a part without a motion engine (the L6474): NOP, SetParam, GetParam
/// and GetStatus as on the others, HardStop's opcode as Enable and HardHiZ's as Disable; every
/// other command is no command there (WRONG_CMD). The reserved opcodes stay reserved.
constexpr Opcode without_motion_engine(Opcode op) {
  switch (op.command) {
    case Command::NOP: case Command::SetParam: case Command::GetParam: case Command::GetStatus:
    case Command::Reserved: case Command::Unknown:
      return op;
    case Command::HardStop: op.command = Command::Enable; return op;
    case Command::HardHiZ: op.command = Command::Disable; return op;
    default: return Opcode{};  // Command::Unknown, no argument bytes
  }
}

/// Classifies an opcode byte without regard to which registers exist.
/// SetParam/GetParam come back with arg_bytes 0; the variant fills in the register length.
constexpr Opcode classify_opcode(std::uint8_t b) {
  Opcode op;
  op.dir = (b & 1u) != 0;
  if (b == 0x00) { op.command = Command::NOP; return op; }
  if (b <= 0x1F) { op.command = Command::SetParam; op.param = b & 0x1F; return op; }
  if (b <= 0x3F) { op.command = Command::GetParam; op.param = b & 0x1F; return op; }
  switch (b & 0xFE) {
    case 0x40: op.command = Command::Move; op.arg_bytes = 3; return op;
    case 0x50: op.command = Command::Run; op.arg_bytes = 3; return op;
    case 0x58: op.command = Command::StepClock; return op;
    case 0x68: op.command = Command::GoTo_DIR; op.arg_bytes = 3; return op;
    case 0x82: case 0x8A:
      op.command = Command::GoUntil; op.act = (b & 0x08) != 0; op.arg_bytes = 3; return op;
    case 0x92: case 0x9A:
      op.command = Command::ReleaseSW; op.act = (b & 0x08) != 0; return op;
    default: break;
  }
  op.dir = false;
  switch (b) {
    case 0x60: op.command = Command::GoTo; op.arg_bytes = 3; return op;
    case 0x70: op.command = Command::GoHome; return op;
    case 0x78: op.command = Command::GoMark; return op;
    case 0xA0: op.command = Command::SoftHiZ; return op;
    case 0xA8: op.command = Command::HardHiZ; return op;
    case 0xB0: op.command = Command::SoftStop; return op;
    case 0xB8: op.command = Command::HardStop; return op;
    case 0xC0: op.command = Command::ResetDevice; return op;
    case 0xD0: op.command = Command::GetStatus; return op;
    case 0xD8: op.command = Command::ResetPos; return op;
    case 0xEB: case 0xF8: op.command = Command::Reserved; return op;
    default: op.command = Command::Unknown; return op;
  }
}

}  // namespace l6470emu
