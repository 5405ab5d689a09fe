// Chip::stck_pulses, the bulk form of STCK a pulse train uses: N pulses at once leave every
// variant, in every step mode and direction, exactly as N single rising edges do (ABS_POS across
// its 22-bit wrap, EL_POS, STATUS, the travel), with and without an axis.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "core/chip.hpp"
#include "core/variant.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

/// A chip of `v` in step-clock mode (the L6474: enabled), STEP_MODE's step selection `sel`,
/// ABS_POS set to `start` first, stepping forward or back.
struct StepClockChip {
  StepClockChip(const Variant& v, std::uint8_t sel, bool forward, std::uint32_t start) : chain(1, v), host(chain) {
    host.set_param(0, Reg::ABS_POS, start);
    const std::uint32_t mode = chain.chip(0).peek(Reg::STEP_MODE);
    host.set_param(0, Reg::STEP_MODE, (mode & ~0x7u) | sel);
    if (v.motion_engine) {
      host.step_clock(0, forward);
    } else {
      chain.chip(0).set_dir_pin(forward);
      host.enable(0);
    }
  }
  Chip& chip() { return chain.chip(0); }
  Chain chain;
  ChainHost host;
};

void expect_same(const Chip& bulk, const Chip& single, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(bulk.peek(Reg::ABS_POS), single.peek(Reg::ABS_POS));
  EXPECT_EQ(bulk.peek(Reg::EL_POS), single.peek(Reg::EL_POS));
  EXPECT_EQ(bulk.peek(Reg::MARK), single.peek(Reg::MARK));
  EXPECT_EQ(bulk.status(), single.status());
  EXPECT_EQ(bulk.motion().travel, single.motion().travel);
}

TEST(StckPulses, NPulsesAtOnceEqualNSingleEdgesForEveryVariantStepModeAndDirection) {
  const std::uint64_t counts[] = {0, 1, 2, 127, 511, 512, 513, 4099};
  for (const Variant* v : all_variants())
    for (std::uint8_t sel = 0; sel < 8; ++sel)
      for (const bool forward : {true, false})
        for (const std::uint64_t n : counts) {
          // Near either end of ABS_POS's 22 bits, so that the larger counts wrap it.
          const std::uint32_t start = forward ? 0x1FFF00u : 0x200100u;
          StepClockChip bulk(*v, sel, forward, start), single(*v, sel, forward, start);
          bulk.chip().stck_pulses(n);
          for (std::uint64_t i = 0; i < n; ++i) {
            single.chip().set_stck_pin(true);
            single.chip().set_stck_pin(false);
          }
          if (n) {
            ASSERT_NE(single.chip().peek(Reg::ABS_POS), start) << "the chip is in step-clock mode";
          }
          expect_same(bulk.chip(), single.chip(),
                      std::string(v->name) + " STEP_SEL " + std::to_string(sel) + (forward ? " forward " : " back ") +
                          std::to_string(n) + " pulses");
        }
}

TEST(StckPulses, APinLeftHighIsTakenLowFirstWithoutAStep) {
  for (const Variant* v : all_variants()) {
    StepClockChip bulk(*v, 2, true, 0), single(*v, 2, true, 0);
    bulk.chip().set_stck_pin(true);
    single.chip().set_stck_pin(true);
    bulk.chip().stck_pulses(5);
    single.chip().set_stck_pin(false);
    for (int i = 0; i < 5; ++i) {
      single.chip().set_stck_pin(true);
      single.chip().set_stck_pin(false);
    }
    expect_same(bulk.chip(), single.chip(), std::string(v->name));
  }
}

TEST(StckPulses, PulsesOutsideStepClockModeOrWithTheBridgesOffMoveNothing) {
  for (const Variant* v : all_variants()) {
    Chain chain(1, *v);  // power-up: HiZ, no StepClock command (the L6474 not enabled)
    chain.chip(0).stck_pulses(1000);
    EXPECT_EQ(chain.chip(0).peek(Reg::ABS_POS), 0u) << v->name;
  }
}

TEST(StckPulses, NPulsesAtOnceEqualNSingleEdgesWithAnAxisAttached) {
  for (const Variant* v : all_variants()) {
    StepClockChip bulk(*v, 3, true, 0), single(*v, 3, true, 0);
    bulk.chip().attach_axis(AxisSpec{});
    single.chip().attach_axis(AxisSpec{});
    bulk.chip().stck_pulses(300);
    for (int i = 0; i < 300; ++i) {
      single.chip().set_stck_pin(true);
      single.chip().set_stck_pin(false);
    }
    expect_same(bulk.chip(), single.chip(), std::string(v->name));
    EXPECT_EQ(bulk.chip().axis()->true_position(), single.chip().axis()->true_position()) << v->name;
  }
}

}  // namespace
}  // namespace l6470emu
