// Register values in physical units, per variant, exactly. Sources: DS70r3 §9.1 (the L6470's
// equations and tables) and the spec's §3.8, §6.1 for the other variants (spec/dspin-reference.md);
// one tick is 250 ns, so step/tick · 4 000 000 = step/s and 4 000 000 = 15625 · 2^8.
#include "core/units.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/near_miss.hpp"

namespace l6470emu {
namespace {

constexpr std::uint64_t k15625 = 15625;

// One LSB of each kind, as (numerator, power-of-two denominator).
constexpr UnitScale speed_scale(std::string_view name, Reg reg, std::uint8_t bits, std::uint64_t den,
                                std::uint16_t offset_halves = 0, std::string_view note = {}) {
  return UnitScale{name, reg, 0, bits, offset_halves, k15625, den, PhysicalUnit::step_per_s, false, note};
}

constexpr std::string_view kIntSpeedNote =
    "CONFLICT: 2^-24 step/tick as the L6470 datasheet and ST's cSPIN library say (0x408 = 246 step/s); "
    "ST's 2014 L6470 driver reads 2^-26";
constexpr std::string_view kSlopeNote =
    "UNCONFIRMED LSB: 2^-16 fits the datasheet's range (0 to 0.004), resolution (0.000015) and reset column "
    "(0.038 %, 0.063 %); ST's libraries use 0.004/255";
constexpr std::string_view kL6472Note = "UNCONFIRMED: one third-party header (no L6472 table was read)";
constexpr std::string_view kL6482OcdNote = "the L6482's scale: one ST library (its cSPIN header)";
constexpr std::string_view kTvalNote = "7.8 mV in the sources: 128 steps up to 1 V make it 7.8125 mV";
// The L6474's scales: ST's drivers (31.25 mA per TVAL step up to 4 A, 0.5 us per TON_MIN/TOFF_MIN
// step up to 64 us, 2 us per T_FAST step, 375 mA per OCD_TH step), docs/l6474.md.
constexpr std::string_view kL6474Note = "ST's L6474 drivers' conversions (docs/l6474.md)";

// Registers every variant has.
#define L6470EMU_MOTION_SCALES(INFINITE_ACC)                                                                                     \
  speed_scale("SPEED", Reg::SPEED, 20, 1u << 20),                                                                 \
      UnitScale{"ACC", Reg::ACC, 0, 12, 0, k15625 * k15625, 1u << 24, PhysicalUnit::step_per_s2, INFINITE_ACC, {}}, \
      UnitScale{"DEC", Reg::DEC, 0, 12, 0, k15625 * k15625, 1u << 24, PhysicalUnit::step_per_s2, false, {}},        \
      speed_scale("MAX_SPEED", Reg::MAX_SPEED, 10, 1u << 10), speed_scale("MIN_SPEED", Reg::MIN_SPEED, 12, 1u << 16)

// Voltage mode: KVAL, BEMF compensation, K_THERM.
#define L6470EMU_VOLTAGE_SCALES                                                                              \
  UnitScale{"KVAL_HOLD", Reg::KVAL_HOLD, 0, 8, 0, 1, 256, PhysicalUnit::fraction_of_VS, false, {}},         \
      UnitScale{"KVAL_RUN", Reg::KVAL_RUN, 0, 8, 0, 1, 256, PhysicalUnit::fraction_of_VS, false, {}},       \
      UnitScale{"KVAL_ACC", Reg::KVAL_ACC, 0, 8, 0, 1, 256, PhysicalUnit::fraction_of_VS, false, {}},       \
      UnitScale{"KVAL_DEC", Reg::KVAL_DEC, 0, 8, 0, 1, 256, PhysicalUnit::fraction_of_VS, false, {}},       \
      speed_scale("INT_SPEED", Reg::INT_SPEED, 14, 1u << 16, 0, kIntSpeedNote),                              \
      UnitScale{"ST_SLP", Reg::ST_SLP, 0, 8, 0, 1, 1u << 16, PhysicalUnit::s_per_step, false, kSlopeNote},   \
      UnitScale{"FN_SLP_ACC", Reg::FN_SLP_ACC, 0, 8, 0, 1, 1u << 16, PhysicalUnit::s_per_step, false, kSlopeNote}, \
      UnitScale{"FN_SLP_DEC", Reg::FN_SLP_DEC, 0, 8, 0, 1, 1u << 16, PhysicalUnit::s_per_step, false, kSlopeNote}, \
      UnitScale{"K_THERM", Reg::K_THERM, 0, 4, 64, 1, 32, PhysicalUnit::factor, false, {}}

#define L6470EMU_ADC_SCALE UnitScale{"ADC_OUT", Reg::ADC_OUT, 0, 5, 0, 1, 32, PhysicalUnit::fraction_of_VREG, false, {}}

// Current mode: the reference, and the off-time settings (microseconds).
#define L6470EMU_CURRENT_TIMES(NOTE)                                                                    \
  UnitScale{"TOFF_FAST", Reg::T_FAST, 4, 4, 2, 2, 1, PhysicalUnit::us, false, NOTE},                    \
      UnitScale{"FAST_STEP", Reg::T_FAST, 0, 4, 2, 2, 1, PhysicalUnit::us, false, NOTE},                \
      UnitScale{"TON_MIN", Reg::TON_MIN, 0, 7, 2, 1, 2, PhysicalUnit::us, false, NOTE},                 \
      UnitScale{"TOFF_MIN", Reg::TOFF_MIN, 0, 7, 2, 1, 2, PhysicalUnit::us, false, NOTE}

#define L6470EMU_TVAL_MV                                                                             \
  UnitScale{"TVAL_HOLD", Reg::TVAL_HOLD, 0, 7, 2, 125, 16, PhysicalUnit::mV, false, kTvalNote},      \
      UnitScale{"TVAL_RUN", Reg::TVAL_RUN, 0, 7, 2, 125, 16, PhysicalUnit::mV, false, kTvalNote},    \
      UnitScale{"TVAL_ACC", Reg::TVAL_ACC, 0, 7, 2, 125, 16, PhysicalUnit::mV, false, kTvalNote},    \
      UnitScale{"TVAL_DEC", Reg::TVAL_DEC, 0, 7, 2, 125, 16, PhysicalUnit::mV, false, kTvalNote}

constexpr UnitScale kL6470[] = {
    L6470EMU_MOTION_SCALES(true),
    L6470EMU_VOLTAGE_SCALES,
    L6470EMU_ADC_SCALE,
    UnitScale{"OCD_TH", Reg::OCD_TH, 0, 4, 2, 375, 1, PhysicalUnit::mA, false, {}},
    UnitScale{"STALL_TH", Reg::STALL_TH, 0, 7, 2, 125, 4, PhysicalUnit::mA, false, {}},
    speed_scale("FS_SPD", Reg::FS_SPD, 10, 1u << 10, 1),
};
constexpr UnitScale kL6480[] = {
    L6470EMU_MOTION_SCALES(true),
    L6470EMU_VOLTAGE_SCALES,
    L6470EMU_ADC_SCALE,
    UnitScale{"OCD_TH", Reg::OCD_TH, 0, 5, 2, 125, 4, PhysicalUnit::mV, false, {}},
    UnitScale{"STALL_TH", Reg::STALL_TH, 0, 5, 2, 125, 4, PhysicalUnit::mV, false, {}},
    speed_scale("FS_SPD", Reg::FS_SPD, 10, 1u << 10, 1),
};
constexpr UnitScale kPowerstep01[] = {
    L6470EMU_MOTION_SCALES(true),
    L6470EMU_VOLTAGE_SCALES,
    L6470EMU_ADC_SCALE,
    UnitScale{"OCD_TH", Reg::OCD_TH, 0, 5, 2, 125, 4, PhysicalUnit::mV, false, {}},
    UnitScale{"STALL_TH", Reg::STALL_TH, 0, 5, 2, 125, 4, PhysicalUnit::mV, false, {}},
    speed_scale("FS_SPD", Reg::FS_SPD, 10, 1u << 10, 1),
    L6470EMU_TVAL_MV,
    L6470EMU_CURRENT_TIMES(std::string_view{}),
};
constexpr UnitScale kL6482[] = {
    L6470EMU_MOTION_SCALES(true),
    L6470EMU_TVAL_MV,
    L6470EMU_CURRENT_TIMES(std::string_view{}),
    L6470EMU_ADC_SCALE,
    UnitScale{"OCD_TH", Reg::OCD_TH, 0, 5, 2, 125, 4, PhysicalUnit::mV, false, kL6482OcdNote},
    speed_scale("FS_SPD", Reg::FS_SPD, 10, 1u << 10, 1),
};
constexpr UnitScale kL6472[] = {
    L6470EMU_MOTION_SCALES(false)  /* ACC = 0xFFF is reserved on the L6472: the emulator treats it as a value */,
    UnitScale{"TVAL_HOLD", Reg::TVAL_HOLD, 0, 7, 2, 125, 4, PhysicalUnit::mA, false, kL6472Note},
    UnitScale{"TVAL_RUN", Reg::TVAL_RUN, 0, 7, 2, 125, 4, PhysicalUnit::mA, false, kL6472Note},
    UnitScale{"TVAL_ACC", Reg::TVAL_ACC, 0, 7, 2, 125, 4, PhysicalUnit::mA, false, kL6472Note},
    UnitScale{"TVAL_DEC", Reg::TVAL_DEC, 0, 7, 2, 125, 4, PhysicalUnit::mA, false, kL6472Note},
    L6470EMU_CURRENT_TIMES(kL6472Note),
    L6470EMU_ADC_SCALE,
    UnitScale{"OCD_TH", Reg::OCD_TH, 0, 4, 2, 375, 1, PhysicalUnit::mA, false,
              "UNCONFIRMED: the L6470's scale, assumed for the L6472 (same width)"},
    speed_scale("FS_SPD", Reg::FS_SPD, 10, 1u << 10, 1),
};
constexpr UnitScale kL6474[] = {
    UnitScale{"TVAL", Reg::TVAL, 0, 7, 2, 125, 4, PhysicalUnit::mA, false, kL6474Note},
    L6470EMU_CURRENT_TIMES(kL6474Note),
    L6470EMU_ADC_SCALE,
    UnitScale{"OCD_TH", Reg::OCD_TH, 0, 4, 2, 375, 1, PhysicalUnit::mA, false, kL6474Note},
};
#undef L6470EMU_MOTION_SCALES
#undef L6470EMU_VOLTAGE_SCALES
#undef L6470EMU_ADC_SCALE
#undef L6470EMU_CURRENT_TIMES
#undef L6470EMU_TVAL_MV

bool same(std::string_view a, std::string_view b) { return same_name(a, b); }

// Removes common factors of two so that the denominator stays the smallest power of two.
PhysicalValue reduced(std::uint64_t num, std::uint64_t den) {
  while (den > 1 && (num % 2) == 0) {
    num /= 2;
    den /= 2;
  }
  return PhysicalValue{num, den, false};
}

std::string shown(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string hex_field(const UnitScale& s, std::uint32_t n) {
  char buf[80];  // "0x", up to 64 digits of width (bits is at most 255: every field is narrower), NUL
  std::snprintf(buf, sizeof buf, "0x%0*X", static_cast<int>((s.bits + 3) / 4), n);
  return buf;
}

}  // namespace

std::string_view unit_symbol(PhysicalUnit unit) {
  switch (unit) {
    case PhysicalUnit::step_per_s: return "step/s";
    case PhysicalUnit::step_per_s2: return "step/s²";
    case PhysicalUnit::mA: return "mA";
    case PhysicalUnit::mV: return "mV";
    case PhysicalUnit::fraction_of_VS: return "VS";
    case PhysicalUnit::s_per_step: return "s/step";
    case PhysicalUnit::us: return "µs";
    case PhysicalUnit::factor: return "x";
    case PhysicalUnit::fraction_of_VREG: return "VREG";
  }
  return "?";
}

double PhysicalValue::to_double() const {
  if (infinite) return HUGE_VAL;
  return static_cast<double>(num) / static_cast<double>(den);
}

std::string PhysicalValue::decimal() const {
  if (infinite) return "inf";
  std::string out = std::to_string(num / den);
  std::uint64_t r = num % den;
  if (r != 0) out += '.';
  while (r != 0) {  // den is a power of two: the digits end
    r *= 10;
    out += static_cast<char>('0' + r / den);
    r %= den;
  }
  return out;
}

std::span<const UnitScale> unit_scales(const Variant& variant) {
  if (&variant == &l6470()) return kL6470;
  if (&variant == &l6472()) return kL6472;
  if (&variant == &l6480()) return kL6480;
  if (&variant == &l6482()) return kL6482;
  if (&variant == &powerstep01() || &variant == powerstep01().current_mode) return kPowerstep01;
  if (&variant == &l6474()) return kL6474;
  return {};
}

const UnitScale* find_unit_scale(const Variant& variant, std::string_view name) {
  if (same(name, "SPD")) name = "SPEED";
  for (const UnitScale& s : unit_scales(variant))
    if (same(s.name, name)) return &s;
  return nullptr;
}

std::string why_no_unit_scale(const Variant& variant, std::string_view name) {
  if (find_unit_scale(variant, name) != nullptr) return "";
  const auto has_register = [&](const Variant& v) -> const RegisterInfo* {
    for (const Variant* t : {&v, v.current_mode})
      if (t != nullptr)
        for (const RegisterInfo& r : t->registers)
          if (same(r.name, name)) return &r;
    return nullptr;
  };
  if (const RegisterInfo* r = has_register(variant)) {
    std::string fields;
    std::size_t count = 0;
    for (const UnitScale& s : unit_scales(variant))
      if (s.reg == r->id) fields += (count++ == 0 ? "" : " and ") + std::string(s.name);
    if (count > 1)
      return std::string(r->name) + " holds " + std::to_string(count) + " values: " + fields + ", each with its own scale";
    return std::string(r->name) + " has no physical unit";
  }
  std::string owners;
  std::vector<std::string> names{"SPD"};
  for (const Variant* v : all_variants()) {
    bool owns = has_register(*v) != nullptr;
    for (const UnitScale& s : unit_scales(*v)) {
      names.emplace_back(s.name);
      owns = owns || same(s.name, name);
    }
    if (owns) owners += (owners.empty() ? "" : ", ") + std::string(v->name);
  }
  if (!owners.empty())
    return std::string(variant.name) + " has no " + std::string(name) + " (a register of " + owners + ")";
  const std::vector<std::string> near = closest_matches(name, names);
  std::string hint;
  for (std::size_t i = 0; i < near.size(); ++i)
    hint += (i == 0 ? "; did you mean '" : i + 1 == near.size() ? " or '" : ", '") + near[i] + "'";
  std::string shown;
  for (unsigned char c : name.substr(0, 40)) shown += (c < 0x20 || c >= 0x7f) ? '?' : static_cast<char>(c);
  return "unknown register '" + shown + "'" + hint + (hint.empty() ? "" : "?");
}

PhysicalValue to_physical(const UnitScale& s, std::uint32_t n) {
  n &= s.max_field();
  if (s.top_is_infinite && n == s.max_field()) return PhysicalValue{0, 1, true};
  return reduced((2ull * n + s.offset_halves) * s.lsb_num, 2ull * s.lsb_den);
}

FieldValue to_register(const UnitScale& s, double x, OutOfRange out_of_range) {
  FieldValue out;
  const std::string unit(unit_symbol(s.unit));
  const auto fail = [&](std::string why) {
    out.error = std::string(s.name) + ": " + std::move(why);
    return out;
  };
  const auto ok = [&](std::uint32_t n) {
    out.ok = true;
    out.n = n;
    return out;
  };
  if (std::isnan(x)) return fail("not a number");
  const std::int64_t top = s.max_finite_field();
  // The ends, in words: only for a refusal's message (the accepted path builds no string).
  const auto low = [&] { return to_physical(s, 0).decimal() + " " + unit + " (" + hex_field(s, 0) + ")"; };
  const auto high = [&] {
    return to_physical(s, static_cast<std::uint32_t>(top)).decimal() + " " + unit + " (" +
           hex_field(s, static_cast<std::uint32_t>(top)) + ")" +
           (s.top_is_infinite ? "; " + hex_field(s, s.max_field()) + " (inf) selects infinite acceleration" : "");
  };
  if (std::isinf(x)) {
    if (x > 0 && s.top_is_infinite) return ok(s.max_field());
    if (out_of_range == OutOfRange::saturate) return ok(x > 0 ? static_cast<std::uint32_t>(top) : 0);
    return fail(x > 0 ? "inf is above the largest value, " + high() : "-inf is below the smallest value, " + low());
  }
  // mid(k): the value halfway between fields k and k + 1, exact in a double (its numerator
  // stays below 2^53 and the denominator is a power of two).
  const auto mid = [&](std::int64_t k) {
    return static_cast<double>((2 * k + 1 + s.offset_halves) * static_cast<std::int64_t>(s.lsb_num)) /
           static_cast<double>(2 * s.lsb_den);
  };
  double guess = x * static_cast<double>(s.lsb_den) / static_cast<double>(s.lsb_num) - s.offset_halves / 2.0;
  guess = std::fmin(std::fmax(guess, -1.0), static_cast<double>(top + 1));
  std::int64_t k = std::llround(guess);
  while (k <= top && x >= mid(k)) ++k;      // nearer k + 1 (a tie goes up)
  while (k >= 0 && x < mid(k - 1)) --k;     // nearer k - 1
  if (k < 0) {
    if (out_of_range == OutOfRange::saturate) return ok(0);
    return fail(shown(x) + " " + unit + " is below the smallest value, " + low());
  }
  if (k > top) {
    if (out_of_range == OutOfRange::saturate) return ok(static_cast<std::uint32_t>(top));
    return fail(shown(x) + " " + unit + " is above the largest value, " + high());
  }
  return ok(static_cast<std::uint32_t>(k));
}

std::string describe_scale(const Variant& variant, const UnitScale& s) {
  std::string n = "n";
  if (s.offset_halves == 1)
    n = "(n + 0.5)";
  else if (s.offset_halves != 0)
    n = "(n + " + reduced(s.offset_halves, 2).decimal() + ")";
  std::string out = n + " · " + reduced(s.lsb_num, s.lsb_den).decimal() + " " + std::string(unit_symbol(s.unit));
  const RegisterInfo* r = variant.find(s.reg);
  if (r == nullptr && variant.current_mode != nullptr) r = variant.current_mode->find(s.reg);
  if (r == nullptr || r->bits != s.bits || s.shift != 0)
    out += ", n = bits " + std::to_string(s.shift + s.bits - 1) + ".." + std::to_string(s.shift);
  return out;
}

}  // namespace l6470emu
