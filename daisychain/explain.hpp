// Commands and register values in words, from the variant tables: opcode names,
// register names and widths come from the table in force; units are added for the
// motion quantities whose scale is the same on every family member.
#pragma once

#include <cstdint>
#include <string>

#include "core/registers.hpp"
#include "core/status_layout.hpp"
#include "core/variant.hpp"

namespace l6470emu {

/// An opcode as the datasheet names it: "GetParam(ABS_POS)", "Move(FWD)", "GetStatus",
/// "unknown opcode 0xEB".
std::string opcode_name(std::uint8_t opcode, const Variant& table);

/// A register value with its meaning: "0x08A = 2008 step/s²", "0x7E03 [HiZ REV STOPPED UVLO]".
std::string describe_value(const RegisterInfo& r, std::uint32_t value, const StatusLayout& layout);

/// A complete command and its argument: "SetParam(ACC, 0x08A = 2008 step/s²)",
/// "Move(FWD, 3200 microsteps)", "Run(REV, SPD 0x04189 = 250.0 step/s)".
std::string describe_command(std::uint8_t opcode, std::uint32_t arg, const Variant& table,
                             const StatusLayout& layout);

/// A GetParam/GetStatus answer: "GetStatus → 0x7E03 [HiZ REV STOPPED UVLO]",
/// "GetParam(ABS_POS) → 0x000C80 = 3200 microsteps".
std::string describe_answer(std::uint8_t opcode, std::uint32_t value, const Variant& table,
                            const StatusLayout& layout);

/// `value` in hex with as many digits as `bits` needs: hex_value(0x8A, 12) = "0x08A".
std::string hex_value(std::uint32_t value, unsigned bits);

}  // namespace l6470emu
