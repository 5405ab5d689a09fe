// The physical meaning of register values (step/s, step/s², mA, mV, fractions of VS, s/step,
// µs) by the datasheets' formulas, both ways, per variant. The model itself never uses these:
// it stays in the registers' integer units; this is for people writing or reading values.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "core/registers.hpp"
#include "core/variant.hpp"

namespace l6470emu {

/// What a register's value is counted in.
enum class PhysicalUnit : std::uint8_t {
  step_per_s,        ///< full steps per second, whatever STEP_SEL says
  step_per_s2,       ///< full steps per second²
  mA,                ///< a current (integrated bridges: L6470, L6472, L6474)
  mV,                ///< a voltage (gate drivers: V_DS of the MOSFETs, or the sense-resistor voltage)
  fraction_of_VS,    ///< KVAL: the share of the supply voltage applied (0 … 255/256)
  s_per_step,        ///< BEMF compensation slope: share of VS per step/s
  us,                ///< microseconds
  factor,            ///< a dimensionless coefficient (K_THERM)
  fraction_of_VREG,  ///< ADC_OUT: ADCIN as a share of VREG
};

/// The unit's symbol as the CLI prints it ("step/s", "step/s²", "mA", "mV", "VS", "s/step", "µs", "x", "VREG").
std::string_view unit_symbol(PhysicalUnit unit);

/// How one register, or one field of it, maps onto a physical quantity. With n the field
/// (`(value >> shift) & (2^bits - 1)`): physical = (2·n + offset_halves) · lsb_num / (2·lsb_den).
/// lsb_den is a power of two, so every physical value is an exact finite decimal.
struct UnitScale {
  std::string_view name;          ///< register name, or a field's name (TOFF_FAST, FAST_STEP of T_FAST)
  Reg reg;                        ///< the register the field lives in
  std::uint8_t shift;             ///< the field's lowest bit
  std::uint8_t bits;              ///< the field's width
  std::uint16_t offset_halves;    ///< added to n, in half LSBs: 0; 1 (FS_SPD: n + 0.5); 2 ((n + 1)·LSB)
  std::uint64_t lsb_num;          ///< one LSB is lsb_num / lsb_den `unit`
  std::uint64_t lsb_den;          ///< a power of two
  PhysicalUnit unit;
  bool top_is_infinite = false;   ///< ACC = 0xFFF selects infinite acceleration on this variant
  std::string_view note{};        ///< where the formula comes from when it is not a datasheet's own ("UNCONFIRMED: ...")

  /// The largest field value.
  constexpr std::uint32_t max_field() const { return (1u << bits) - 1u; }
  /// The largest field value with a finite physical value (0xFFE for ACC with top_is_infinite).
  constexpr std::uint32_t max_finite_field() const { return max_field() - (top_is_infinite ? 1u : 0u); }
  /// The field's bits within the register.
  constexpr std::uint32_t field_mask() const { return max_field() << shift; }
  /// The field of a register value (T_FAST = 0x19: TOFF_FAST 1, FAST_STEP 9).
  constexpr std::uint32_t field_of(std::uint32_t register_value) const { return (register_value >> shift) & max_field(); }
};

/// An exact physical value: num / den (den a power of two), or infinity.
struct PhysicalValue {
  std::uint64_t num = 0;
  std::uint64_t den = 1;
  bool infinite = false;

  /// The value as a double: exact (num < 2^53 and den a power of two for every scale).
  double to_double() const;
  /// Every digit: "991.8212890625", "13422", "inf".
  std::string decimal() const;
};

/// The variant's scales, in address order; the powerSTEP01's include its current-mode
/// registers (TVAL_*, T_FAST's fields, TON_MIN, TOFF_MIN) after the voltage-mode ones.
std::span<const UnitScale> unit_scales(const Variant& variant);

/// The scale called `name` on `variant` (case-insensitive; "SPD", the Run/GoUntil argument, is
/// SPEED's scale), or nullptr. For T_FAST, which holds two times, this is nullptr: ask for
/// TOFF_FAST or FAST_STEP.
const UnitScale* find_unit_scale(const Variant& variant, std::string_view name);

/// Why `name` has no scale on `variant`, in one line: "unknown register 'MAX_SPED'; did you
/// mean 'MAX_SPEED'?", "L6470 has no TVAL_RUN (a register of L6472, L6482, powerSTEP01)",
/// "CONFIG has no physical unit", "T_FAST holds two values: TOFF_FAST and FAST_STEP"; "" when
/// it has one.
std::string why_no_unit_scale(const Variant& variant, std::string_view name);

/// The physical value of field value `n` (0 … max_field()); n above it is masked.
PhysicalValue to_physical(const UnitScale& scale, std::uint32_t n);

/// What to do with a physical value outside the field's range.
enum class OutOfRange : std::uint8_t { refuse, saturate };

/// A physical → field conversion: the field value, or a one-line reason it has none.
struct FieldValue {
  bool ok = false;
  std::uint32_t n = 0;
  std::string error;  ///< "MAX_SPEED: 20000 step/s is above the largest, 15610.3515625 step/s (0x3FF)"
};

/// The field value whose physical value is nearest to `physical` (in the scale's unit; a tie
/// goes to the larger value, as rounding the datasheets' formulas to the nearest integer does).
/// Values whose nearest field value would be below 0 or above max_finite_field() are refused
/// with a message, or with OutOfRange::saturate give the nearest end. +infinity gives the top
/// value where it means infinite acceleration; NaN is always refused. Exact: for every n,
/// to_register(s, to_physical(s, n).to_double()) gives n back.
FieldValue to_register(const UnitScale& scale, double physical, OutOfRange out_of_range = OutOfRange::refuse);

/// The scale in words: "(n + 1) · 375 mA", "(n + 0.5) · 15.2587890625 step/s, n = bits 9..0"
/// (the bits are named when the field is not the whole register of `variant`).
std::string describe_scale(const Variant& variant, const UnitScale& scale);

}  // namespace l6470emu
