// Physical units of register values: the datasheet's check values, exact round trips over every
// field value of every scale of every variant, rounding to the nearest value, and refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "core/near_miss.hpp"
#include "core/units.hpp"

namespace l6470emu {
namespace {

const UnitScale& scale(const Variant& v, std::string_view name) {
  const UnitScale* s = find_unit_scale(v, name);
  EXPECT_NE(s, nullptr) << v.name << " " << name;
  static const UnitScale none{};
  return s != nullptr ? *s : none;
}

double phys(const Variant& v, std::string_view name, std::uint32_t n) { return to_physical(scale(v, name), n).to_double(); }

std::uint32_t reg(const Variant& v, std::string_view name, double x) {
  const FieldValue f = to_register(scale(v, name), x);
  EXPECT_TRUE(f.ok) << f.error;
  return f.n;
}

TEST(Units, TheDatasheetsCheckValuesComeOut) {
  const Variant& v = l6470();
  EXPECT_EQ(reg(v, "SPEED", 200.0), 13422u);  // 200 · 2^28 · 250 ns = 13421.77
  EXPECT_EQ(to_physical(scale(v, "MAX_SPEED"), 0x041).decimal(), "991.8212890625");
  EXPECT_NEAR(phys(v, "ACC", 0x08A), 2008.16, 0.01);
  EXPECT_NEAR(phys(v, "FS_SPD", 0x027), 602.7, 0.05);
  EXPECT_NEAR(phys(v, "FS_SPD", 0), 7.63, 0.01);     // "about 7.63 step/s" at FS_SPD = 0
  EXPECT_NEAR(phys(v, "MIN_SPEED", 0xFFF), 976.3, 0.05);
  EXPECT_NEAR(phys(v, "MAX_SPEED", 0x3FF), 15610, 1);
  EXPECT_NEAR(phys(v, "INT_SPEED", 0x408), 246, 0.1);
  EXPECT_NEAR(phys(v, "KVAL_RUN", 0x29), 0.16, 0.001);
  EXPECT_NEAR(phys(v, "ST_SLP", 0x19) * 100, 0.038, 0.0005);   // "0.038% s/step"
  EXPECT_NEAR(phys(v, "FN_SLP_ACC", 0x29) * 100, 0.063, 0.0005);
  EXPECT_EQ(phys(v, "K_THERM", 0), 1.0);
  EXPECT_EQ(phys(v, "K_THERM", 15), 1.46875);
  EXPECT_EQ(phys(v, "OCD_TH", 0x8), 3375.0);  // "3.38 A"
  EXPECT_EQ(phys(v, "OCD_TH", 0xF), 6000.0);
  EXPECT_EQ(phys(v, "STALL_TH", 0x40), 2031.25);  // "2.03 A"
  EXPECT_EQ(phys(v, "STALL_TH", 0x7F), 4000.0);
  EXPECT_EQ(phys(v, "ADC_OUT", 16), 0.5);
}

TEST(Units, GateDriversCountThresholdsInMillivoltsAndCurrentModeInMicroseconds) {
  EXPECT_EQ(phys(l6480(), "OCD_TH", 31), 1000.0);
  EXPECT_EQ(phys(l6480(), "STALL_TH", 0), 31.25);
  EXPECT_EQ(phys(l6482(), "TVAL_RUN", 127), 1000.0);
  EXPECT_EQ(phys(l6482(), "TVAL_RUN", 0), 7.8125);
  EXPECT_EQ(phys(powerstep01(), "TVAL_HOLD", 0x29), 42 * 7.8125);
  EXPECT_EQ(phys(powerstep01(), "KVAL_HOLD", 0x29), 41.0 / 256);  // both readings of 0x09
  EXPECT_EQ(phys(l6482(), "TON_MIN", 0), 0.5);
  EXPECT_EQ(phys(l6482(), "TOFF_MIN", 127), 64.0);
  EXPECT_EQ(phys(l6482(), "TOFF_FAST", scale(l6482(), "TOFF_FAST").field_of(0x19)), 4.0);  // T_FAST = 0x19
  EXPECT_EQ(phys(l6482(), "FAST_STEP", scale(l6482(), "FAST_STEP").field_of(0x19)), 20.0);
  EXPECT_EQ(phys(l6472(), "TVAL_RUN", 127), 4000.0);  // UNCONFIRMED: 31.25 mA steps
  EXPECT_FALSE(find_unit_scale(l6472(), "TVAL_RUN")->note.empty());
  EXPECT_EQ(find_unit_scale(l6482(), "T_FAST"), nullptr);  // two fields: ask for one
  EXPECT_EQ(find_unit_scale(l6482(), "KVAL_RUN"), nullptr);
  EXPECT_EQ(find_unit_scale(l6470(), "TVAL_RUN"), nullptr);
  EXPECT_EQ(find_unit_scale(l6470(), "spd"), find_unit_scale(l6470(), "SPEED"));
}

TEST(Units, EveryFieldValueOfEveryScaleRoundTripsExactly) {
  std::size_t checked = 0;
  for (const Variant* v : all_variants()) {
    for (const UnitScale& s : unit_scales(*v)) {
      for (std::uint32_t n = 0; n <= s.max_field(); ++n) {
        const PhysicalValue p = to_physical(s, n);
        const FieldValue back = to_register(s, p.to_double());
        ASSERT_TRUE(back.ok) << v->name << " " << s.name << " " << n << ": " << back.error;
        ASSERT_EQ(back.n, n) << v->name << " " << s.name << " via " << p.decimal();
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 5u * (1u << 20));  // SPEED's 2^20 values on each variant, at least
}

TEST(Units, PhysicalValuesRoundToTheNearestFieldValueAndTiesGoUp) {
  const UnitScale& s = scale(l6470(), "MAX_SPEED");  // 15.2587890625 step/s per LSB
  EXPECT_EQ(to_register(s, 15.2587890625 * 12.49).n, 12u);
  EXPECT_EQ(to_register(s, 15.2587890625 * 12.51).n, 13u);
  EXPECT_EQ(to_register(s, 15.2587890625 * 12.5).n, 13u);  // exactly halfway
  EXPECT_EQ(to_register(s, std::nextafter(15.2587890625 * 12.5, 0.0)).n, 12u);
  EXPECT_EQ(to_register(s, -0.001).n, 0u);  // nearest is 0
  const UnitScale& fs = scale(l6470(), "FS_SPD");  // (n + 0.5) LSB
  EXPECT_EQ(to_register(fs, 7.0).n, 0u);
  EXPECT_EQ(to_register(fs, 15.2587890625 * 1.0).n, 1u);  // (1 + 0.5) - 0.5: the tie goes up
  const UnitScale& ocd = scale(l6470(), "OCD_TH");  // (n + 1) · 375 mA
  EXPECT_EQ(to_register(ocd, 3000).n, 7u);
  EXPECT_EQ(to_register(ocd, 200).n, 0u);  // nearer 375 mA than nothing below it
}

TEST(Units, OutOfRangeValuesAreRefusedWithAReasonOrSaturated) {
  const UnitScale& s = scale(l6470(), "MAX_SPEED");
  FieldValue f = to_register(s, 20000);
  EXPECT_FALSE(f.ok);
  EXPECT_EQ(f.error, "MAX_SPEED: 20000 step/s is above the largest value, 15609.7412109375 step/s (0x3FF)");
  f = to_register(s, -8);
  EXPECT_EQ(f.error, "MAX_SPEED: -8 step/s is below the smallest value, 0 step/s (0x000)");
  EXPECT_EQ(to_register(s, 20000, OutOfRange::saturate).n, 0x3FFu);
  EXPECT_EQ(to_register(s, -8, OutOfRange::saturate).n, 0u);
  EXPECT_EQ(to_register(s, NAN, OutOfRange::saturate).error, "MAX_SPEED: not a number");
  EXPECT_EQ(to_register(scale(l6470(), "OCD_TH"), 100).error,
            "OCD_TH: 100 mA is below the smallest value, 375 mA (0x0)");
}

TEST(Units, AccOfAllOnesIsInfiniteWhereItMeansInfiniteAcceleration) {
  for (const Variant* v : all_variants()) {
    if (!v->has(Reg::ACC)) continue;  // the L6474: no speed profile
    const UnitScale& acc = scale(*v, "ACC");
    EXPECT_EQ(acc.top_is_infinite, v->infinite_acceleration) << v->name;
    EXPECT_FALSE(scale(*v, "DEC").top_is_infinite) << v->name;
  }
  const UnitScale& acc = scale(l6470(), "ACC");
  EXPECT_TRUE(to_physical(acc, 0xFFF).infinite);
  EXPECT_EQ(to_register(acc, INFINITY).n, 0xFFFu);
  EXPECT_EQ(to_register(acc, 59575.5).n, 0xFFEu);
  const FieldValue f = to_register(acc, 59590);
  EXPECT_FALSE(f.ok);
  EXPECT_NE(f.error.find("0xFFF (inf) selects infinite acceleration"), std::string::npos) << f.error;
  EXPECT_NEAR(phys(l6472(), "ACC", 0xFFF), 59590, 1);  // reserved there: an ordinary value
}

TEST(Units, EveryScaleFitsItsRegisterAndEveryPhysicalRegisterHasOne) {
  const std::set<Reg> physical = {Reg::SPEED,     Reg::ACC,      Reg::DEC,        Reg::MAX_SPEED,  Reg::MIN_SPEED,
                                  Reg::FS_SPD,    Reg::INT_SPEED, Reg::KVAL_HOLD, Reg::KVAL_RUN,   Reg::KVAL_ACC,
                                  Reg::KVAL_DEC,  Reg::ST_SLP,   Reg::FN_SLP_ACC, Reg::FN_SLP_DEC, Reg::K_THERM,
                                  Reg::ADC_OUT,   Reg::OCD_TH,   Reg::STALL_TH,   Reg::TVAL_HOLD,  Reg::TVAL_RUN,
                                  Reg::TVAL_ACC,  Reg::TVAL_DEC, Reg::T_FAST,     Reg::TON_MIN,    Reg::TOFF_MIN,
                                  Reg::TVAL};
  for (const Variant* v : all_variants()) {
    for (const Variant* table : {v, v->current_mode}) {
      if (table == nullptr) continue;
      for (const RegisterInfo& r : table->registers) {
        bool found = false;
        for (const UnitScale& s : unit_scales(*v)) {
          if (s.reg != r.id) continue;
          found = true;
          EXPECT_LE(s.shift + s.bits, r.bits) << v->name << " " << s.name;
        }
        EXPECT_EQ(found, physical.count(r.id) == 1) << v->name << " " << r.name;
      }
    }
  }
}

TEST(Units, ScalesAreDescribedInWords) {
  EXPECT_EQ(describe_scale(l6470(), scale(l6470(), "OCD_TH")), "(n + 1) · 375 mA");
  EXPECT_EQ(describe_scale(l6480(), scale(l6480(), "FS_SPD")), "(n + 0.5) · 15.2587890625 step/s, n = bits 9..0");
  EXPECT_EQ(describe_scale(l6470(), scale(l6470(), "K_THERM")), "(n + 32) · 0.03125 x");
  EXPECT_EQ(describe_scale(l6482(), scale(l6482(), "TOFF_FAST")), "(n + 1) · 2 µs, n = bits 7..4");
  EXPECT_EQ(describe_scale(l6474(), scale(l6474(), "TVAL")), "(n + 1) · 31.25 mA");
}

TEST(Units, L6474TvalIs31p25mAPerStepUpTo4AAndItsTimesAreTheL6472s) {
  // ST's L6474 drivers: TVAL 31.25 mA to 4 A, TON_MIN/TOFF_MIN 0.5 to 64 us, OCD_TH 375 mA steps.
  EXPECT_EQ(phys(l6474(), "TVAL", 0), 31.25);
  EXPECT_EQ(phys(l6474(), "TVAL", 0x29), 1312.5);
  EXPECT_EQ(phys(l6474(), "TVAL", 127), 4000.0);
  EXPECT_EQ(reg(l6474(), "TVAL", 1312.5), 0x29u);
  EXPECT_EQ(phys(l6474(), "TON_MIN", 0x29), 21.0);
  EXPECT_EQ(phys(l6474(), "TOFF_MIN", 127), 64.0);
  EXPECT_EQ(phys(l6474(), "TOFF_FAST", 1), 4.0);   // T_FAST reset 0x19: 4 us and 20 us
  EXPECT_EQ(phys(l6474(), "FAST_STEP", 9), 20.0);
  EXPECT_EQ(phys(l6474(), "OCD_TH", 0x8), 3375.0);
  EXPECT_EQ(find_unit_scale(l6474(), "MAX_SPEED"), nullptr);
  EXPECT_EQ(why_no_unit_scale(l6474(), "MAX_SPEED"),
            "L6474 has no MAX_SPEED (a register of L6470, L6472, L6480, L6482, powerSTEP01)");
}

TEST(NearMiss, SuggestsTheClosestNames) {
  EXPECT_EQ(closest_names("replya", {"replay", "decode", "convert"}), "replay");
  EXPECT_EQ(closest_names("L6471", {"L6470", "L6472", "L6480"}), "L6470 or L6472");
  EXPECT_EQ(closest_names("xyz", {"replay"}), "");
  EXPECT_EQ(variant_suggestion("powrSTEP01"), "did you mean powerSTEP01? ");
}

}  // namespace
}  // namespace l6470emu
