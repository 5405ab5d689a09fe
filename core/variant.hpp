// A chip variant as data: its register table, STATUS layout, ALARM_EN meaning
// and a few capabilities (pins, whether it has a motion engine). There is no class per
// variant; the model reads these.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string_view>

#include "core/commands.hpp"
#include "core/registers.hpp"
#include "core/status_layout.hpp"

namespace l6470emu {

/// A register bit the datasheet reserves, to be written 0 (the driver sanitizer's RESERVED_BITS).
struct ReservedBit {
  Reg reg;
  std::uint8_t bit;
  std::string_view source;  ///< where it is stated: "§9.1.19 Table 17, note 1: write 0"
};

/// The pins a part has beside FLAG, STCK and STBY\RST (which every member has).
struct VariantPins {
  bool busy_sync = true;  ///< BUSY\SYNC output (not on the L6474)
  bool sw = true;         ///< SW input (not on the L6474)
  bool dir = false;       ///< DIR input: the direction STCK steps in (the L6474 only)
};

/// Everything that distinguishes one family member from another.
struct Variant {
  std::string_view name;                   ///< "L6470", ...
  std::span<const RegisterInfo> registers; ///< ascending addresses
  StatusLayout status;                     ///< STATUS bit positions
  AlarmLayout alarms;                      ///< ALARM_EN bit meanings
  std::uint8_t max_step_sel = 7;           ///< finest STEP_SEL (7 = 1/128)
  bool infinite_acceleration = true;       ///< ACC = 0xFFF skips the ramps
  /// The powerSTEP01's reading of the same registers when STEP_MODE.CM_VM = 1 (current
  /// mode), or nullptr. Storage is shared: only names, widths and meanings change.
  const Variant* current_mode = nullptr;
  /// ResetDevice is refused (CMD_ERROR) while the bridges are enabled (community report).
  bool reset_device_needs_hiz = false;
  /// The choices made where the sources are single or silent (UNCONFIRMED), in words.
  std::span<const std::string_view> unconfirmed{};
  /// Table index of each address (0..31), -1 for a hole or a reserved address.
  std::array<std::int8_t, 32> index_of_address{};
  /// Table index of each register id, -1 when the variant has no such register.
  std::array<std::int8_t, static_cast<std::size_t>(Reg::count)> index_of_reg{};
  /// Every opcode byte decoded for this variant: SetParam/GetParam of an address the
  /// variant lacks is Unknown, SetParam carries the register's SPI length.
  std::array<Opcode, 256> opcodes{};
  /// Bits to be written 0 (STEP_MODE bit 3 on the L6470/L6480, CONFIG bit 6), for the sanitizer.
  std::span<const ReservedBit> reserved_bits{};
  /// False on the L6474: no speed profile generator and no motion commands (their opcodes are
  /// unknown commands); the position moves one microstep at each STCK rising edge while the
  /// bridges are enabled, in the direction the DIR pin gives. Set by drop_motion_engine().
  bool motion_engine = true;
  /// The pins the part has.
  VariantPins pins{};

  /// The register at `address`, or nullptr when the variant has none there.
  constexpr const RegisterInfo* at_address(std::uint8_t address) const {
    if (address >= 32) return nullptr;
    const auto i = index_of_address[address];
    return i < 0 ? nullptr : &registers[static_cast<std::size_t>(i)];
  }
  /// The description of `id`, or nullptr when the variant lacks it.
  constexpr const RegisterInfo* find(Reg id) const {
    const auto i = index_of_reg[static_cast<std::size_t>(id)];
    return i < 0 ? nullptr : &registers[static_cast<std::size_t>(i)];
  }
  /// Whether the variant has register `id`.
  constexpr bool has(Reg id) const { return find(id) != nullptr; }
};

/// Builds a Variant from its table, filling in the derived look-ups.
constexpr Variant make_variant(std::string_view name, std::span<const RegisterInfo> table,
                               StatusLayout status, AlarmLayout alarms,
                               std::uint8_t max_step_sel, bool infinite_acceleration) {
  Variant v{name, table, status, alarms, max_step_sel, infinite_acceleration, nullptr, false, {}, {}, {}, {}};
  for (auto& i : v.index_of_address) i = -1;
  for (auto& i : v.index_of_reg) i = -1;
  for (std::size_t i = 0; i < table.size(); ++i) {
    v.index_of_address[table[i].address] = static_cast<std::int8_t>(i);
    v.index_of_reg[static_cast<std::size_t>(table[i].id)] = static_cast<std::int8_t>(i);
  }
  for (unsigned b = 0; b < 256; ++b) {
    Opcode op = classify_opcode(static_cast<std::uint8_t>(b));
    if (op.command == Command::SetParam || op.command == Command::GetParam) {
      const RegisterInfo* r = v.at_address(op.param);
      if (r == nullptr)
        op.command = Command::Unknown;
      else if (op.command == Command::SetParam)
        op.arg_bytes = r->spi_bytes();
    }
    v.opcodes[b] = op;
  }
  return v;
}

/// Makes `v` a part without a motion engine (the L6474): its opcodes become
/// without_motion_engine()'s (Enable, Disable, GetStatus, GetParam, SetParam, NOP), and it has
/// DIR where the others have BUSY\SYNC and SW.
constexpr void drop_motion_engine(Variant& v) {
  v.motion_engine = false;
  v.pins = VariantPins{.busy_sync = false, .sw = false, .dir = true};
  for (Opcode& op : v.opcodes) op = without_motion_engine(op);
}

/// Checks a register table at compile time: unique ascending addresses in 0x01..0x1F,
/// widths of 1..24 bits, reset values inside the width, live registers read-only or positions.
constexpr bool register_table_is_consistent(std::span<const RegisterInfo> table) {
  unsigned previous = 0;
  for (const auto& r : table) {
    if (r.address <= previous || r.address > 0x1F) return false;
    if (r.bits == 0 || r.bits > 24) return false;
    if ((r.reset & ~r.mask()) != 0) return false;
    if (r.spi_bytes() < 1 || r.spi_bytes() > 3) return false;
    previous = r.address;
  }
  return true;
}

/// The L6470 (dSPIN, voltage mode, integrated bridges).
const Variant& l6470();
/// The L6472 (dSPIN, current mode, integrated bridges).
const Variant& l6472();
/// The L6480 (cSPIN, voltage mode, gate driver).
const Variant& l6480();
/// The L6482 (cSPIN, current mode, gate driver).
const Variant& l6482();
/// The powerSTEP01 (voltage or current mode by STEP_MODE.CM_VM, power stage in package),
/// in its power-up voltage mode; current_mode points at its current-mode reading.
const Variant& powerstep01();
/// The L6474 (easySPIN: current mode, integrated bridges, no motion engine: STCK and DIR move it).
const Variant& l6474();

/// Every family member, in the order above.
std::span<const Variant* const> all_variants();

/// Whether two datasheet names are the same ignoring ASCII case ("ABS_POS" and "abs_pos").
bool same_name(std::string_view a, std::string_view b);

/// The variant called `name` (case-insensitive: "L6470", "l6480", "powerSTEP01", "powerstep01"), or nullptr.
const Variant* find_variant(std::string_view name);

}  // namespace l6470emu
