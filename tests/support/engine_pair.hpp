// Two chips fed the same bytes, pins and time, one on the event-driven engine and one on the
// tick-by-tick reference, for the property tests that require them to agree.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <initializer_list>

#include "core/chip.hpp"

namespace l6470emu::test {

struct EnginePair {
  Chip fast;
  Chip ref;
  EnginePair() {
    fast.set_motion_engine(MotionEngine::fast);
    ref.set_motion_engine(MotionEngine::reference);
  }
  void attach(const AxisSpec& spec) {
    fast.attach_axis(spec);
    ref.attach_axis(spec);
  }
  void bytes(std::initializer_list<std::uint8_t> b) {
    for (auto x : b) {
      fast.on_byte(x);
      ref.on_byte(x);
    }
  }
  void cmd3(std::uint8_t op, std::uint32_t v) {
    bytes({op, static_cast<std::uint8_t>(v >> 16), static_cast<std::uint8_t>(v >> 8), static_cast<std::uint8_t>(v)});
  }
  void set2(std::uint8_t addr, std::uint32_t v) { bytes({addr, static_cast<std::uint8_t>(v >> 8), static_cast<std::uint8_t>(v)}); }
  void set1(std::uint8_t addr, std::uint32_t v) { bytes({addr, static_cast<std::uint8_t>(v)}); }
  void advance_to(Tick t) {
    fast.advance_to(t);
    ref.advance_to(t);
  }
  void sw(bool level) {
    fast.set_sw_pin(level);
    ref.set_sw_pin(level);
  }
  void stck(bool level) {
    fast.set_stck_pin(level);
    ref.set_stck_pin(level);
  }
};

/// Whether the two chips show the same positions, speed, MARK, STATUS, BUSY and FLAG and have
/// the same whole motion state.
inline ::testing::AssertionResult same_motion(const Chip& f, const Chip& r) {
  for (Reg id : {Reg::ABS_POS, Reg::EL_POS, Reg::SPEED, Reg::MARK, Reg::STATUS})
    if (f.peek(id) != r.peek(id))
      return ::testing::AssertionFailure() << "register " << static_cast<int>(id) << " fast=" << f.peek(id)
                                           << " reference=" << r.peek(id) << " at tick " << r.now();
  if (f.busy_sync_pin() != r.busy_sync_pin()) return ::testing::AssertionFailure() << "BUSY pin differs at tick " << r.now();
  if (f.flag_pin() != r.flag_pin()) return ::testing::AssertionFailure() << "FLAG pin differs at tick " << r.now();
  if (!(f.motion() == r.motion()))
    return ::testing::AssertionFailure() << "motion state differs at tick " << r.now() << ": speed " << f.motion().speed
                                         << " vs " << r.motion().speed << ", frac " << f.motion().frac << " vs "
                                         << r.motion().frac;
  return ::testing::AssertionSuccess();
}

}  // namespace l6470emu::test
