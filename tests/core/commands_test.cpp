// The L6470 command set (spec §5, datasheet §9.2): opcode classification, what each
// command does, unknown opcodes, missing addresses and the acceptance rules, all through SPI.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/chip.hpp"
#include "core/commands.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;

// ---------------------------------------------------------------- helpers


constexpr unsigned kStopped = 0, kAcceleration = 1, kDeceleration = 2, kConstantSpeed = 3;

const std::uint32_t kSpd300 = test::spd_from_steps_per_s(300);  // Run/GoUntil SPD for 300 step/s

std::string hex(unsigned v) {
  std::ostringstream s;
  s << "0x" << std::hex << std::uppercase << v;
  return s.str();
}

std::vector<std::uint8_t> send(test::OneChip& rig, std::vector<std::uint8_t> bytes) { return rig.host.send(0, bytes); }

/// An opcode with a 3-byte argument, MSB first.
std::vector<std::uint8_t> cmd3(std::uint8_t opcode, std::uint32_t arg) {
  return {opcode, static_cast<std::uint8_t>(arg >> 16), static_cast<std::uint8_t>(arg >> 8),
          static_cast<std::uint8_t>(arg)};
}

std::vector<std::uint8_t> set_param_bytes(std::uint8_t address, std::uint32_t value, unsigned bytes) {
  std::vector<std::uint8_t> tx{address};
  for (unsigned i = bytes; i-- > 0;) tx.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
  return tx;
}

/// STATUS as GetParam(STATUS) returns it on SPI (does not clear anything).
std::uint16_t read_status(test::OneChip& rig) {
  const auto rx = send(rig, {0x39, 0x00, 0x00});
  EXPECT_EQ(rx[0], 0x00);
  return static_cast<std::uint16_t>(rx[1] << 8 | rx[2]);
}

/// GetStatus: the answer, and the latched flags are cleared.
std::uint16_t get_status(test::OneChip& rig) {
  const auto rx = send(rig, {0xD0, 0x00, 0x00});
  EXPECT_EQ(rx[0], 0x00);
  return static_cast<std::uint16_t>(rx[1] << 8 | rx[2]);
}

std::uint32_t get_param(test::OneChip& rig, std::uint8_t address, unsigned bytes) {
  std::vector<std::uint8_t> tx(bytes + 1, 0x00);
  tx[0] = static_cast<std::uint8_t>(0x20 | address);
  const auto rx = send(rig, tx);
  EXPECT_EQ(rx[0], 0x00);
  std::uint32_t v = 0;
  for (unsigned i = 1; i <= bytes; ++i) v = v << 8 | rx[i];
  return v;
}

std::uint32_t abs_pos(test::OneChip& rig) { return get_param(rig, 0x01, 3); }
std::uint32_t pos22(std::int32_t p) { return static_cast<std::uint32_t>(p) & 0x3FFFFF; }

// SPI value lengths from spec §2.1 (index = address; 0 = no register).
constexpr unsigned kSpiBytes[32] = {0, 3, 2, 3, 3, 2, 2, 2, 2, 1, 1, 1, 1, 2, 1, 1,
                                    1, 1, 1, 1, 1, 2, 1, 1, 2, 2, 0, 0, 0, 0, 0, 0};

/// Every opcode byte of the command table (spec §5.1), with SetParam/GetParam of existing addresses.
std::set<unsigned> command_table_opcodes() {
  std::set<unsigned> s{0x00, 0x40, 0x41, 0x50, 0x51, 0x58, 0x59, 0x60, 0x68, 0x69, 0x70, 0x78,
                       0x82, 0x83, 0x8A, 0x8B, 0x92, 0x93, 0x9A, 0x9B, 0xA0, 0xA8, 0xB0, 0xB8,
                       0xC0, 0xD0, 0xD8};
  for (unsigned a = 0x01; a <= 0x19; ++a) {
    s.insert(a);         // SetParam
    s.insert(0x20 | a);  // GetParam
  }
  return s;
}

/// Bytes that are no command of the L6470: everything outside the table, the two RESERVED codes,
/// and SetParam/GetParam of addresses the L6470 lacks (0x00 for GetParam, 0x1A..0x1F for both).
std::vector<unsigned> non_commands() {
  const auto valid = command_table_opcodes();
  std::vector<unsigned> out;
  for (unsigned b = 0; b < 256; ++b)
    if (!valid.count(b)) out.push_back(b);
  return out;
}

/// Two chips that see the same frames at the same times; only `probe` gets the command under
/// test (the `control` gets NOPs instead), so "state unchanged" can be checked while the motor runs.
struct Twin {
  test::OneChip probe;
  test::OneChip control;

  void both(const std::vector<std::uint8_t>& bytes) {
    send(probe, bytes);
    send(control, bytes);
  }
  void wait_ms(std::uint64_t ms) {
    probe.host.wait_ms(ms);
    control.host.wait_ms(ms);
  }
  void clear_flags() {
    get_status(probe);
    get_status(control);
  }
  /// Sends `bytes` to the probe only, one frame each; returns NOTPERF_CMD after each frame.
  std::vector<bool> probe_only(const std::vector<std::uint8_t>& bytes) {
    std::vector<bool> notperf;
    for (auto b : bytes) {
      send(probe, {b});
      send(control, {0x00});
      notperf.push_back((probe.chip().status() & kNotPerf) != 0);
    }
    return notperf;
  }
};

/// NOTPERF_CMD only after the last byte.
std::vector<bool> only_last(std::size_t n) {
  std::vector<bool> v(n, false);
  v.back() = true;
  return v;
}

void expect_same_state(const Chip& a, const Chip& b, std::uint16_t ignore_status_bits = 0) {
  for (const RegisterInfo& r : a.variant().registers) {
    if (r.id == Reg::STATUS) continue;
    EXPECT_EQ(a.peek(r.id), b.peek(r.id)) << r.name;
  }
  EXPECT_EQ(a.status() & ~ignore_status_bits, b.status() & ~ignore_status_bits)
      << hex(a.status()) << " vs " << hex(b.status());
  EXPECT_TRUE(a.motion() == b.motion()) << "motion state differs";
  EXPECT_EQ(a.hiz(), b.hiz());
  EXPECT_EQ(a.now(), b.now());
}

/// The refused command raised NOTPERF_CMD and changed nothing else.
void expect_refused(const Twin& t) {
  EXPECT_NE(t.probe.chain.chip(0).status() & kNotPerf, 0);
  EXPECT_EQ(t.control.chain.chip(0).status() & kNotPerf, 0);
  expect_same_state(t.probe.chain.chip(0), t.control.chain.chip(0), kNotPerf);
}

/// Both chips running forward at 300 step/s target, still accelerating (BUSY low), flags cleared.
void start_running(Twin& t) {
  t.both(cmd3(0x51, kSpd300));
  t.wait_ms(20);
  t.clear_flags();
  ASSERT_EQ(t.probe.chip().status() & kBusyN, 0) << "motor should still be accelerating";
}

// ---------------------------------------------------------------- classification

struct Classified {
  std::uint8_t byte;
  Command command;
  std::uint8_t args;
  bool dir;
  bool act;
};

TEST(ClassifyOpcode, NamesEveryCommandOfTheCommandTableWithItsArgumentLengthAndBits) {
  const Classified table[] = {
      {0x00, Command::NOP, 0, false, false},        {0x50, Command::Run, 3, false, false},
      {0x51, Command::Run, 3, true, false},         {0x58, Command::StepClock, 0, false, false},
      {0x59, Command::StepClock, 0, true, false},   {0x40, Command::Move, 3, false, false},
      {0x41, Command::Move, 3, true, false},        {0x60, Command::GoTo, 3, false, false},
      {0x68, Command::GoTo_DIR, 3, false, false},   {0x69, Command::GoTo_DIR, 3, true, false},
      {0x82, Command::GoUntil, 3, false, false},    {0x83, Command::GoUntil, 3, true, false},
      {0x8A, Command::GoUntil, 3, false, true},     {0x8B, Command::GoUntil, 3, true, true},
      {0x92, Command::ReleaseSW, 0, false, false},  {0x93, Command::ReleaseSW, 0, true, false},
      {0x9A, Command::ReleaseSW, 0, false, true},   {0x9B, Command::ReleaseSW, 0, true, true},
      {0x70, Command::GoHome, 0, false, false},     {0x78, Command::GoMark, 0, false, false},
      {0xD8, Command::ResetPos, 0, false, false},   {0xC0, Command::ResetDevice, 0, false, false},
      {0xB0, Command::SoftStop, 0, false, false},   {0xB8, Command::HardStop, 0, false, false},
      {0xA0, Command::SoftHiZ, 0, false, false},    {0xA8, Command::HardHiZ, 0, false, false},
      {0xD0, Command::GetStatus, 0, false, false},  {0xEB, Command::Reserved, 0, false, false},
      {0xF8, Command::Reserved, 0, false, false},
  };
  for (const auto& want : table) {
    SCOPED_TRACE(hex(want.byte));
    const Opcode op = classify_opcode(want.byte);
    EXPECT_EQ(op.command, want.command) << to_string(op.command);
    EXPECT_EQ(op.arg_bytes, want.args);
    const bool has_dir = want.command == Command::Run || want.command == Command::Move ||
                         want.command == Command::StepClock || want.command == Command::GoTo_DIR ||
                         want.command == Command::GoUntil || want.command == Command::ReleaseSW;
    if (has_dir) {
      EXPECT_EQ(op.dir, want.dir);
    }
    if (want.command == Command::GoUntil || want.command == Command::ReleaseSW) {
      EXPECT_EQ(op.act, want.act);
    }
  }
}

TEST(ClassifyOpcode, SetParamAndGetParamCarryTheFiveBitParamField) {
  for (unsigned b = 0x01; b <= 0x1F; ++b) {
    const Opcode op = classify_opcode(static_cast<std::uint8_t>(b));
    EXPECT_EQ(op.command, Command::SetParam) << hex(b);
    EXPECT_EQ(op.param, b) << hex(b);
  }
  for (unsigned b = 0x20; b <= 0x3F; ++b) {
    const Opcode op = classify_opcode(static_cast<std::uint8_t>(b));
    EXPECT_EQ(op.command, Command::GetParam) << hex(b);
    EXPECT_EQ(op.param, b & 0x1F) << hex(b);
    EXPECT_EQ(op.arg_bytes, 0) << hex(b);
  }
}

TEST(ClassifyOpcode, CallsEveryByteOutsideTheCommandTableUnknown) {
  auto valid = command_table_opcodes();
  for (unsigned a = 0x1A; a <= 0x1F; ++a) valid.insert(a);       // SetParam: the variant decides
  for (unsigned a = 0x20; a <= 0x3F; ++a) valid.insert(a);       // GetParam: the variant decides
  for (unsigned b = 0; b < 256; ++b) {
    if (valid.count(b) || b == 0xEB || b == 0xF8) continue;
    EXPECT_EQ(classify_opcode(static_cast<std::uint8_t>(b)).command, Command::Unknown) << hex(b);
  }
}

TEST(ClassifyOpcode, UsesTheDatasheetCommandNames) {
  EXPECT_EQ(to_string(Command::GoTo_DIR), "GoTo_DIR");
  EXPECT_EQ(to_string(Command::ReleaseSW), "ReleaseSW");
  EXPECT_EQ(to_string(Command::GetStatus), "GetStatus");
  EXPECT_EQ(to_string(Command::SetParam), "SetParam");
  EXPECT_EQ(to_string(Command::HardHiZ), "HardHiZ");
}

// ---------------------------------------------------------------- decoding over SPI

TEST(CommandDecoder, AcceptsEveryOpcodeOfTheCommandTableWithoutWrongCmd) {
  for (unsigned b : command_table_opcodes()) {
    SCOPED_TRACE(hex(b));
    if (b == 0x04 || b == 0x12 || b == 0x19) continue;  // SetParam of read-only: quirks_test
    test::OneChip rig;
    std::vector<std::uint8_t> tx{static_cast<std::uint8_t>(b)};
    unsigned extra = classify_opcode(static_cast<std::uint8_t>(b)).arg_bytes;
    if (b >= 0x01 && b <= 0x3F) extra = kSpiBytes[b & 0x1F];  // value bytes or answer bytes
    tx.resize(1 + extra, 0x00);
    send(rig, tx);
    EXPECT_EQ(rig.chip().status() & kWrongCmd, 0);
  }
}

TEST(CommandDecoder, RaisesWrongCmdAtEveryByteThatIsNoCommandAndDecodesTheNextByteAsACommand) {
  for (unsigned b : non_commands()) {
    SCOPED_TRACE(hex(b));
    test::OneChip rig;
    EXPECT_EQ(send(rig, {static_cast<std::uint8_t>(b)}), std::vector<std::uint8_t>{0x00});
    EXPECT_EQ(rig.chip().status(), 0x7C03 | kWrongCmd) << "WRONG_CMD at the command byte, nothing else";
    // The next byte is a command of its own: GetParam(KVAL_HOLD) answers at once.
    EXPECT_EQ(send(rig, {0x29, 0x00}), (std::vector<std::uint8_t>{0x00, 0x29}));
  }
}

TEST(CommandDecoder, TreatsTheReservedOpcodes0xEBAnd0xF8AsUnknownCommands) {
  for (std::uint8_t b : {0xEB, 0xF8}) {
    test::OneChip rig;
    // If a reserved code took argument bytes, the GetParam below would be swallowed.
    EXPECT_EQ(send(rig, {b, 0x29, 0x00}), (std::vector<std::uint8_t>{0x00, 0x00, 0x29})) << hex(b);
    EXPECT_NE(rig.chip().status() & kWrongCmd, 0) << hex(b);
  }
}

TEST(CommandDecoder, TreatsOpcodesWithNonZeroFixedBitsAsUnknownCommands) {
  // 0x52 looks like Run, 0x61 like GoTo, 0x42 like Move, 0x6A like GoTo_DIR, 0x84 like GoUntil:
  // none of them may collect three argument bytes.
  for (std::uint8_t b : {0x52, 0x54, 0x61, 0x42, 0x6A, 0x84, 0x86, 0x71, 0x5A, 0x94, 0xA1, 0xB1, 0xC1, 0xD1, 0xD9, 0xFF}) {
    test::OneChip rig;
    EXPECT_EQ(send(rig, {b, 0x29, 0x00, 0x00}), (std::vector<std::uint8_t>{0x00, 0x00, 0x29, 0x00})) << hex(b);
    EXPECT_NE(rig.chip().status() & kWrongCmd, 0) << hex(b);
    EXPECT_EQ(rig.chip().status() & kNotPerf, 0) << hex(b);
  }
}

TEST(CommandDecoder, IgnoresAWrongCommandApartFromTheFlag) {
  test::OneChip rig;
  send(rig, cmd3(0x51, kSpd300));
  rig.host.wait_ms(5);
  test::OneChip twin;
  send(twin, cmd3(0x51, kSpd300));
  twin.host.wait_ms(5);
  send(rig, {0x61});
  send(twin, {0x00});
  expect_same_state(rig.chip(), twin.chip(), kWrongCmd);
}

// ---------------------------------------------------------------- missing addresses

TEST(GetParam, OfAddressZeroRaisesWrongCmdAtTheCommandByteAndAnswersNothing) {
  test::OneChip rig;
  EXPECT_EQ(send(rig, {0x20}), std::vector<std::uint8_t>{0x00});
  EXPECT_NE(rig.chip().status() & kWrongCmd, 0);
  EXPECT_EQ(send(rig, {0x00, 0x00, 0x00}), (std::vector<std::uint8_t>{0x00, 0x00, 0x00}));
}

TEST(GetParam, OfReservedAddresses0x1AUpTo0x1FRaisesWrongCmdAndTheNextByteIsACommand) {
  for (std::uint8_t a = 0x1A; a <= 0x1F; ++a) {
    SCOPED_TRACE(hex(a));
    test::OneChip rig;
    send(rig, {static_cast<std::uint8_t>(0x20 | a)});
    EXPECT_NE(rig.chip().status() & kWrongCmd, 0) << "at the command byte";
    EXPECT_EQ(send(rig, {0x29, 0x00}), (std::vector<std::uint8_t>{0x00, 0x29}));
  }
}

TEST(SetParam, OfReservedAddresses0x1AUpTo0x1FRaisesWrongCmdAndTheFollowingBytesAreCommands) {
  for (std::uint8_t a = 0x1A; a <= 0x1F; ++a) {
    SCOPED_TRACE(hex(a));
    test::OneChip rig;
    send(rig, {a});
    EXPECT_NE(rig.chip().status() & kWrongCmd, 0) << "at the command byte";
    send(rig, {0x0A, 0x55});  // SetParam(KVAL_RUN, 0x55), not value bytes of the reserved register
    EXPECT_EQ(rig.chip().peek(Reg::KVAL_RUN), 0x55u);
    EXPECT_EQ(rig.chip().status() & kNotPerf, 0);
  }
}

TEST(Nop, IsNotSetParamOfAddressZero) {
  test::OneChip rig;
  EXPECT_EQ(send(rig, {0x00, 0x29, 0x00}), (std::vector<std::uint8_t>{0x00, 0x00, 0x29}));
  EXPECT_EQ(rig.chip().status(), 0x7C03);
}

// ---------------------------------------------------------------- what each command does

TEST(Nop, ChangesNothingAndAnswersZero) {
  test::OneChip rig;
  test::OneChip twin;
  EXPECT_EQ(send(rig, {0x00, 0x00, 0x00}), (std::vector<std::uint8_t>{0, 0, 0}));
  twin.host.wait(3 * 8);
  expect_same_state(rig.chip(), twin.chip());
}

TEST(GetParam, ReturnsTheValueLatchedWhenItsOpcodeIsDecoded) {
  test::OneChip rig;
  send(rig, cmd3(0x51, kSpd300));
  rig.host.wait_ms(100);
  send(rig, {0x21});  // GetParam(ABS_POS)
  const std::uint32_t at_decode = rig.chip().peek(Reg::ABS_POS);
  rig.host.wait_ms(50);
  ASSERT_NE(rig.chip().peek(Reg::ABS_POS), at_decode) << "the motor should have moved on";
  const auto rx = send(rig, {0x00, 0x00, 0x00});
  EXPECT_EQ(rx, (std::vector<std::uint8_t>{static_cast<std::uint8_t>(at_decode >> 16),
                                           static_cast<std::uint8_t>(at_decode >> 8),
                                           static_cast<std::uint8_t>(at_decode)}));
}

TEST(GetStatus, AnswersStatusMsbFirstInTheTwoFollowingBytes) {
  test::OneChip rig;
  EXPECT_EQ(send(rig, {0xD0, 0x00, 0x00, 0x00}), (std::vector<std::uint8_t>{0x00, 0x7C, 0x03, 0x00}));
}

TEST(Run, AcceleratesToSpdInTheGivenDirectionAndReleasesBusyThere) {
  test::OneChip rig;
  send(rig, cmd3(0x51, kSpd300));
  std::uint16_t s = read_status(rig);
  EXPECT_EQ(s & kHiZ, 0) << "Run takes the bridges out of HiZ";
  EXPECT_EQ(s & kBusyN, 0) << "BUSY low until the target speed is reached";
  EXPECT_NE(s & kDir, 0) << "forward";
  EXPECT_EQ(mot(s), kAcceleration);
  rig.host.wait_ms(300);
  s = read_status(rig);
  EXPECT_NE(s & kBusyN, 0);
  EXPECT_EQ(mot(s), kConstantSpeed);
  EXPECT_EQ(get_param(rig, 0x04, 3), kSpd300) << "SPEED has the unit of SPD";
  EXPECT_GT(static_cast<std::int32_t>(rig.chip().position()), 0);
}

TEST(Run, ReverseRunsTowardsNegativePositions) {
  test::OneChip rig;
  send(rig, cmd3(0x50, kSpd300));
  rig.host.wait_ms(50);
  const std::uint16_t s = read_status(rig);
  EXPECT_EQ(s & kDir, 0);
  EXPECT_LT(rig.chip().position(), 0);
}

TEST(Run, AboveMaxSpeedRunsAtMaxSpeed) {
  test::OneChip rig;
  send(rig, set_param_bytes(0x05, 0xFFF, 2));  // ACC = 0xFFF: infinite acceleration
  send(rig, cmd3(0x51, 0xFFFFF));
  rig.host.wait_ms(1);
  // MAX_SPEED 0x041 in 2^-18 step/tick = SPEED 0x041 << 10 in 2^-28 step/tick.
  EXPECT_EQ(get_param(rig, 0x04, 3), 0x041u << 10);
}

TEST(StepClock, EntersStepClockModeAndEachStckRisingEdgeMakesOneMicrostep) {
  test::OneChip rig;
  send(rig, {0x59});
  std::uint16_t s = read_status(rig);
  EXPECT_NE(s & kSckMod, 0);
  EXPECT_NE(s & kDir, 0);
  EXPECT_NE(s & kBusyN, 0) << "StepClock does not pull BUSY low";
  EXPECT_EQ(mot(s), kStopped);
  for (int i = 0; i < 3; ++i) {
    rig.chip().set_stck_pin(true);
    rig.chip().set_stck_pin(false);
  }
  EXPECT_EQ(abs_pos(rig), 3u);
  send(rig, {0x58});  // new direction, still step-clock mode
  rig.chip().set_stck_pin(true);
  EXPECT_EQ(abs_pos(rig), 2u);
  EXPECT_NE(read_status(rig) & kSckMod, 0);
  EXPECT_EQ(get_param(rig, 0x04, 3), 0u) << "SPEED";
}

TEST(StepClock, ModeIsLeftByAConstantSpeedCommand) {
  test::OneChip rig;
  send(rig, {0x59});
  send(rig, cmd3(0x51, kSpd300));
  EXPECT_EQ(read_status(rig) & kSckMod, 0);
}

TEST(Move, MakesNStepMicrostepsAndReleasesBusy) {
  test::OneChip rig;
  send(rig, cmd3(0x41, 1000));
  std::uint16_t s = read_status(rig);
  EXPECT_EQ(s & kBusyN, 0);
  EXPECT_EQ(s & kHiZ, 0);
  rig.host.wait_ms(500);
  s = read_status(rig);
  EXPECT_NE(s & kBusyN, 0);
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_EQ(abs_pos(rig), 1000u);
  EXPECT_EQ(get_param(rig, 0x02, 2), 1000u % 512) << "EL_POS counts 1/128 steps modulo 4 full steps";
}

TEST(Move, ReverseMovesToNegativePositions) {
  test::OneChip rig;
  send(rig, cmd3(0x40, 100));
  rig.host.wait_ms(300);
  EXPECT_EQ(abs_pos(rig), pos22(-100));
}

TEST(GoTo, TakesTheShortestPathToTheAbsolutePosition) {
  test::OneChip rig;
  send(rig, cmd3(0x60, pos22(-50)));
  EXPECT_EQ(read_status(rig) & kDir, 0) << "reverse is shorter";
  rig.host.wait_ms(300);
  EXPECT_EQ(abs_pos(rig), pos22(-50));
  send(rig, cmd3(0x60, 70));
  EXPECT_NE(read_status(rig) & kDir, 0) << "forward is shorter";
  rig.host.wait_ms(300);
  EXPECT_EQ(abs_pos(rig), 70u);
  EXPECT_NE(read_status(rig) & kBusyN, 0);
}

TEST(GoToDir, ForcesTheDirectionEvenTheLongWayRound) {
  test::OneChip rig;
  send(rig, cmd3(0x68, 100));  // reverse to +100
  rig.host.wait_ms(50);
  std::uint16_t s = read_status(rig);
  EXPECT_EQ(s & kDir, 0);
  EXPECT_EQ(s & kBusyN, 0);
  EXPECT_LT(rig.chip().position(), 0);

  test::OneChip fwd;
  send(fwd, cmd3(0x69, pos22(-100)));  // forward to -100
  fwd.host.wait_ms(50);
  s = read_status(fwd);
  EXPECT_NE(s & kDir, 0);
  EXPECT_GT(fwd.chip().position(), 0);
}

TEST(GoToDir, ReachesATargetInTheForcedDirection) {
  test::OneChip rig;
  send(rig, cmd3(0x69, 300));
  rig.host.wait_ms(500);
  EXPECT_EQ(abs_pos(rig), 300u);
}

TEST(GoHome, GoesToPositionZero) {
  test::OneChip rig;
  send(rig, set_param_bytes(0x01, 200, 3));
  send(rig, {0x70});
  EXPECT_EQ(read_status(rig) & kDir, 0);
  rig.host.wait_ms(500);
  EXPECT_EQ(abs_pos(rig), 0u);
  EXPECT_NE(read_status(rig) & kBusyN, 0);
}

TEST(GoMark, GoesToTheMarkPosition) {
  test::OneChip rig;
  send(rig, set_param_bytes(0x03, pos22(-30), 3));
  send(rig, {0x78});
  rig.host.wait_ms(500);
  EXPECT_EQ(abs_pos(rig), pos22(-30));
  EXPECT_EQ(get_param(rig, 0x03, 3), pos22(-30)) << "MARK unchanged";
}

TEST(GoUntil, WithActZeroResetsAbsPosAtTheSwitchTurnOnEventThenStops) {
  test::OneChip rig;
  send(rig, set_param_bytes(0x18, 0x2E98, 2));  // CONFIG.SW_MODE = 1: SoftStop at the event
  send(rig, cmd3(0x83, kSpd300));
  rig.host.wait_ms(50);
  ASSERT_GT(rig.chip().position(), 0);
  EXPECT_EQ(read_status(rig) & kBusyN, 0);
  rig.chip().set_sw_pin(false);
  EXPECT_EQ(rig.chip().peek(Reg::ABS_POS), 0u) << "ABS_POS reset at the edge";
  std::uint16_t s = read_status(rig);
  EXPECT_NE(s & kSwEvn, 0);
  EXPECT_EQ(mot(s), kDeceleration) << "SoftStop with SW_MODE = 1";
  EXPECT_EQ(s & kBusyN, 0) << "BUSY low until the motor is stopped";
  rig.host.wait_ms(500);
  s = read_status(rig);
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_NE(s & kBusyN, 0);
  EXPECT_EQ(s & kHiZ, 0);
}

TEST(GoUntil, WithActOneCopiesAbsPosIntoMarkAndWithSwModeZeroStopsHard) {
  test::OneChip rig;
  send(rig, cmd3(0x8B, kSpd300));
  rig.host.wait_ms(50);
  const std::uint32_t p = rig.chip().peek(Reg::ABS_POS);
  ASSERT_NE(p, 0u);
  rig.chip().set_sw_pin(false);
  EXPECT_EQ(get_param(rig, 0x03, 3), p) << "MARK";
  EXPECT_EQ(abs_pos(rig), p) << "ABS_POS kept";
  const std::uint16_t s = read_status(rig);
  EXPECT_EQ(mot(s), kStopped) << "HardStop interrupt";
  EXPECT_NE(s & kBusyN, 0);
  EXPECT_EQ(get_param(rig, 0x04, 3), 0u);
}

TEST(ReleaseSW, RunsAtFiveStepsPerSecondUntilTheSwitchOpensThenResetsAbsPosAndStops) {
  test::OneChip rig;
  rig.chip().set_sw_pin(false);
  send(rig, {0x93});  // ReleaseSW ACT = 0 forward
  rig.host.wait_ms(100);
  std::uint16_t s = read_status(rig);
  EXPECT_EQ(s & kBusyN, 0);
  EXPECT_NEAR(test::steps_per_s_from_speed(get_param(rig, 0x04, 3)), 5.0, 0.02)
      << "MIN_SPEED below 5 step/s: 5 step/s";
  EXPECT_GT(rig.chip().position(), 0);
  rig.chip().set_sw_pin(true);
  EXPECT_EQ(abs_pos(rig), 0u);
  s = read_status(rig);
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_NE(s & kBusyN, 0);
  EXPECT_EQ(s & kHiZ, 0) << "HardStop keeps the bridges enabled";
}

TEST(ReleaseSW, WithActOneCopiesAbsPosIntoMark) {
  test::OneChip rig;
  rig.chip().set_sw_pin(false);
  send(rig, {0x9A});  // ReleaseSW ACT = 1 reverse
  rig.host.wait_ms(100);
  rig.chip().set_sw_pin(true);
  const std::uint32_t p = abs_pos(rig);
  EXPECT_NE(p, 0u);
  EXPECT_EQ(get_param(rig, 0x03, 3), p);
  EXPECT_LT(rig.chip().position(), 0);
}

TEST(ResetPos, SetsAbsPosToZeroAndLeavesMarkAndElPos) {
  test::OneChip rig;
  send(rig, set_param_bytes(0x01, 1234, 3));
  send(rig, set_param_bytes(0x02, 0x155, 2));
  send(rig, set_param_bytes(0x03, 77, 3));
  send(rig, {0xD8});
  EXPECT_EQ(abs_pos(rig), 0u);
  EXPECT_EQ(get_param(rig, 0x02, 2), 0x155u);
  EXPECT_EQ(get_param(rig, 0x03, 3), 77u);
}

TEST(ResetPos, WorksWhileTheMotorRuns) {
  test::OneChip rig;
  send(rig, cmd3(0x51, kSpd300));
  rig.host.wait_ms(100);
  ASSERT_GT(rig.chip().position(), 0);
  send(rig, {0xD8});
  EXPECT_EQ(rig.chip().peek(Reg::ABS_POS), 0u);
  EXPECT_EQ(rig.chip().status() & kNotPerf, 0);
  EXPECT_NE(mot(rig.chip().status()), kStopped) << "the motor keeps running";
}

TEST(ResetDevice, ReturnsARunningChipToThePowerUpState) {
  test::OneChip rig;
  send(rig, set_param_bytes(0x0A, 0x77, 1));
  send(rig, cmd3(0x51, kSpd300));
  send(rig, {0xEB});
  rig.host.wait_ms(50);
  send(rig, {0xC0});
  EXPECT_EQ(get_param(rig, 0x04, 3), 0u) << "SPEED";
  EXPECT_EQ(abs_pos(rig), 0u);
  EXPECT_EQ(get_param(rig, 0x0A, 1), 0x29u);
  EXPECT_EQ(get_status(rig), 0x7C03) << "HiZ, UVLO latched, nothing else";
  EXPECT_TRUE(rig.chip().hiz());
}

TEST(ResetDevice, WithTheSwitchClosedLeavesHiZAndThenRefusesWhWrites) {
  // Spec §9 item 1: SW low when the logic starts is a turn-on event; with SW_MODE = 0 (reset value)
  // that is a HardStop interrupt, so the bridges leave HiZ and WH registers are no longer writable.
  test::OneChip rig;
  rig.chip().set_sw_pin(false);
  send(rig, {0xC0});
  EXPECT_EQ(read_status(rig), 0x7C0E) << "UVLO latched, SW_F, SW_EVN, bridges enabled";
  send(rig, set_param_bytes(0x0E, 0x30, 1));  // ST_SLP (WH)
  EXPECT_NE(read_status(rig) & kNotPerf, 0);
  EXPECT_EQ(get_param(rig, 0x0E, 1), 0x19u);
}

TEST(SoftStop, DeceleratesThenHoldsWithTheBridgesEnabled) {
  test::OneChip rig;
  send(rig, cmd3(0x51, kSpd300));
  rig.host.wait_ms(200);
  send(rig, {0xB0});
  std::uint16_t s = read_status(rig);
  EXPECT_EQ(mot(s), kDeceleration);
  EXPECT_EQ(s & kBusyN, 0);
  EXPECT_GT(get_param(rig, 0x04, 3), 0u);
  rig.host.wait_ms(500);
  s = read_status(rig);
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_NE(s & kBusyN, 0);
  EXPECT_EQ(s & kHiZ, 0);
  EXPECT_EQ(get_param(rig, 0x04, 3), 0u);
}

TEST(HardStop, StopsAtOnceWithTheBridgesEnabled) {
  test::OneChip rig;
  send(rig, cmd3(0x51, kSpd300));
  rig.host.wait_ms(200);
  send(rig, {0xB8});
  const std::uint16_t s = read_status(rig);
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_NE(s & kBusyN, 0);
  EXPECT_EQ(s & kHiZ, 0);
  EXPECT_EQ(get_param(rig, 0x04, 3), 0u);
}

TEST(SoftHiZ, DeceleratesThenDisablesTheBridges) {
  test::OneChip rig;
  send(rig, cmd3(0x51, kSpd300));
  rig.host.wait_ms(200);
  send(rig, {0xA0});
  std::uint16_t s = read_status(rig);
  EXPECT_EQ(mot(s), kDeceleration);
  EXPECT_EQ(s & kHiZ, 0) << "bridges stay on while decelerating";
  rig.host.wait_ms(500);
  s = read_status(rig);
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_NE(s & kHiZ, 0);
  EXPECT_NE(s & kBusyN, 0);
}

TEST(HardHiZ, DisablesTheBridgesAtOnce) {
  test::OneChip rig;
  send(rig, cmd3(0x51, kSpd300));
  rig.host.wait_ms(200);
  send(rig, {0xA8});
  const std::uint16_t s = read_status(rig);
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_NE(s & kHiZ, 0);
  EXPECT_EQ(get_param(rig, 0x04, 3), 0u);
}

TEST(SoftStopAndHardStop, TakeTheBridgesOutOfHiZWithoutMotion) {
  for (std::uint8_t op : {0xB0, 0xB8}) {
    test::OneChip rig;
    send(rig, {op});
    const std::uint16_t s = read_status(rig);
    EXPECT_EQ(s & kHiZ, 0) << hex(op);
    EXPECT_EQ(mot(s), kStopped) << hex(op);
    EXPECT_NE(s & kBusyN, 0) << hex(op);
    EXPECT_EQ(rig.chip().position(), 0) << hex(op);
  }
}

TEST(SoftHiZAndHardHiZ, PutAStoppedMotorInHiZAtOnce) {
  for (std::uint8_t op : {0xA0, 0xA8}) {
    test::OneChip rig;
    send(rig, {0xB8});
    ASSERT_FALSE(rig.chip().hiz());
    send(rig, {op});
    EXPECT_NE(read_status(rig) & kHiZ, 0) << hex(op);
  }
}

TEST(MotionCommands, EveryOneTakesTheBridgesOutOfHiZ) {
  const std::vector<std::vector<std::uint8_t>> commands = {
      cmd3(0x51, kSpd300), cmd3(0x41, 10), cmd3(0x60, 10), cmd3(0x69, 10), cmd3(0x83, kSpd300),
      {0x93}, {0x70}, {0x78}, {0x59}, {0xB0}, {0xB8}};
  for (const auto& c : commands) {
    SCOPED_TRACE(hex(c[0]));
    test::OneChip rig;
    send(rig, c);
    EXPECT_EQ(read_status(rig) & kHiZ, 0);
  }
}

// ---------------------------------------------------------------- acceptance rules (spec §5.2)

TEST(Move, WhileTheMotorRunsRaisesNotPerfAtTheLastArgumentByteAndChangesNothing) {
  Twin t;
  start_running(t);
  EXPECT_EQ(t.probe_only(cmd3(0x41, 100)), only_last(4));
  expect_refused(t);
}

TEST(Move, IsAcceptedWithTheBridgesEnabledAndTheMotorStopped) {
  test::OneChip rig;
  send(rig, {0xB8});
  get_status(rig);
  send(rig, cmd3(0x41, 10));
  EXPECT_EQ(rig.chip().status() & kNotPerf, 0);
  rig.host.wait_ms(200);
  EXPECT_EQ(abs_pos(rig), 10u);
}

TEST(Move, IsAcceptedInStepClockModeWhereTheMotorCountsAsStopped) {
  test::OneChip rig;
  send(rig, {0x59});
  send(rig, cmd3(0x41, 10));
  EXPECT_EQ(rig.chip().status() & kNotPerf, 0);
  EXPECT_EQ(rig.chip().status() & kSckMod, 0) << "a motion command leaves step-clock mode";
  rig.host.wait_ms(200);
  EXPECT_EQ(abs_pos(rig), 10u);
}

TEST(GoTo, WhileBusyRaisesNotPerfAtTheLastArgumentByteAndChangesNothing) {
  Twin t;
  start_running(t);
  EXPECT_EQ(t.probe_only(cmd3(0x60, 5000)), only_last(4));
  expect_refused(t);
}

TEST(GoToDir, WhileAMoveIsUnderWayRaisesNotPerfAtTheLastArgumentByte) {
  Twin t;
  t.both(cmd3(0x41, 20000));
  t.wait_ms(10);
  t.clear_flags();
  EXPECT_EQ(t.probe_only(cmd3(0x68, 0)), only_last(4));
  expect_refused(t);
}

TEST(GoHomeAndGoMark, WhileBusyRaiseNotPerfAndChangeNothing) {
  for (std::uint8_t op : {0x70, 0x78}) {
    SCOPED_TRACE(hex(op));
    Twin t;
    t.both(set_param_bytes(0x03, 5, 3));
    start_running(t);
    EXPECT_EQ(t.probe_only({op}), only_last(1));
    expect_refused(t);
  }
}

TEST(GoTo, IsAcceptedWhileARunCruisesAtItsTargetSpeedBecauseBusyIsReleased) {
  test::OneChip rig;
  send(rig, cmd3(0x51, kSpd300));
  rig.host.wait_ms(300);
  std::uint16_t s = get_status(rig);
  ASSERT_NE(s & kBusyN, 0) << "the Run has reached its speed";
  const std::int32_t target = rig.chip().position() + 20000;
  send(rig, cmd3(0x60, pos22(target)));
  s = read_status(rig);
  EXPECT_EQ(s & kNotPerf, 0);
  EXPECT_EQ(s & kBusyN, 0) << "GoTo keeps BUSY low until the target";
  rig.host.wait_ms(1500);
  EXPECT_EQ(abs_pos(rig), pos22(target));
  s = read_status(rig);
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_NE(s & kBusyN, 0);
}

TEST(StepClock, WhileTheMotorRunsRaisesNotPerfAndChangesNothing) {
  Twin t;
  start_running(t);
  EXPECT_EQ(t.probe_only({0x58}), only_last(1));
  expect_refused(t);
}

TEST(StepClock, WhileDeceleratingAfterSoftStopIsRefused) {
  Twin t;
  start_running(t);
  t.both({0xB0});
  t.clear_flags();
  EXPECT_EQ(t.probe_only({0x59}), only_last(1));
  expect_refused(t);
}

TEST(SetParam, OfEveryWsRegisterWhileTheMotorRunsRaisesNotPerfAtTheLastValueByteAndChangesNothing) {
  const std::uint8_t ws[] = {0x01, 0x02, 0x05, 0x06, 0x08, 0x17};  // ABS_POS EL_POS ACC DEC MIN_SPEED ALARM_EN
  for (std::uint8_t a : ws) {
    SCOPED_TRACE(hex(a));
    Twin t;
    start_running(t);
    const auto tx = set_param_bytes(a, 0x11, kSpiBytes[a]);
    EXPECT_EQ(t.probe_only(tx), only_last(tx.size()));
    expect_refused(t);
  }
}

TEST(SetParam, OfEveryWhRegisterWithTheBridgesEnabledRaisesNotPerfAtTheLastValueByte) {
  // INT_SPEED ST_SLP FN_SLP_ACC FN_SLP_DEC STEP_MODE CONFIG, motor stopped but bridges enabled.
  const std::uint8_t wh[] = {0x0D, 0x0E, 0x0F, 0x10, 0x16, 0x18};
  for (std::uint8_t a : wh) {
    SCOPED_TRACE(hex(a));
    Twin t;
    t.both({0xB8});  // HardStop: out of HiZ, no motion
    t.clear_flags();
    const auto tx = set_param_bytes(a, 0x03, kSpiBytes[a]);
    EXPECT_EQ(t.probe_only(tx), only_last(tx.size()));
    expect_refused(t);
  }
}

TEST(SetParam, OfStepModeWhileStoppedButNotInHiZReadsStatus0x7E82) {
  // Spec §9 item 2 (community thread): status 0x7E8x after such a write.
  test::OneChip rig;
  get_status(rig);
  send(rig, {0xB8});
  send(rig, set_param_bytes(0x16, 0x00, 1));
  EXPECT_EQ(get_status(rig), 0x7E82);
  EXPECT_EQ(get_param(rig, 0x16, 1), 0x07u) << "STEP_MODE unchanged";
}

TEST(SetParam, OfAWsRegisterIsAcceptedWithTheMotorStoppedAndTheBridgesEnabled) {
  test::OneChip rig;
  send(rig, {0xB8});
  send(rig, set_param_bytes(0x05, 0x123, 2));
  EXPECT_EQ(rig.chip().status() & kNotPerf, 0);
  EXPECT_EQ(get_param(rig, 0x05, 2), 0x123u);
}

TEST(SetParam, OfAWsRegisterIsAcceptedInStepClockMode) {
  test::OneChip rig;
  send(rig, {0x59});
  send(rig, set_param_bytes(0x06, 0x123, 2));
  EXPECT_EQ(rig.chip().status() & kNotPerf, 0);
  EXPECT_EQ(get_param(rig, 0x06, 2), 0x123u);
}

TEST(SetParam, OfEveryWrRegisterIsAcceptedWhileTheMotorRuns) {
  // MARK MAX_SPEED KVAL_* K_THERM OCD_TH STALL_TH FS_SPD
  const std::uint8_t wr[] = {0x03, 0x07, 0x09, 0x0A, 0x0B, 0x0C, 0x11, 0x13, 0x14, 0x15};
  for (std::uint8_t a : wr) {
    SCOPED_TRACE(hex(a));
    test::OneChip rig;
    send(rig, cmd3(0x51, kSpd300));
    rig.host.wait_ms(20);
    send(rig, set_param_bytes(a, 0x05, kSpiBytes[a]));
    EXPECT_EQ(rig.chip().status() & kNotPerf, 0);
    EXPECT_EQ(get_param(rig, a, kSpiBytes[a]), 0x05u);
  }
}

TEST(SetParam, RefusedKeepsConsumingItsValueBytesAndTheNextByteIsACommand) {
  test::OneChip rig;
  send(rig, {0xB8});
  // SetParam(CONFIG) refused (WH): its two value bytes 0x29 0x00 must not be decoded as GetParam.
  EXPECT_EQ(send(rig, {0x18, 0x29, 0x00, 0x00}), (std::vector<std::uint8_t>{0, 0, 0, 0}));
  EXPECT_EQ(send(rig, {0x29, 0x00}), (std::vector<std::uint8_t>{0x00, 0x29}));
}

// ---------------------------------------------------------------- don't-care argument bits

/// Sends `a` to one chip and `b` to another, lets them run and compares their whole state.
void expect_same_effect(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b,
                        const std::vector<std::uint8_t>& setup = {}) {
  test::OneChip x, y;
  if (!setup.empty()) {
    send(x, setup);
    send(y, setup);
  }
  send(x, a);
  send(y, b);
  expect_same_state(x.chip(), y.chip());
  x.host.wait_ms(30);
  y.host.wait_ms(30);
  expect_same_state(x.chip(), y.chip());
}

TEST(Run, IgnoresTheTopFourBitsOfTheFirstSpdByte) {
  expect_same_effect(cmd3(0x51, kSpd300), cmd3(0x51, 0xF00000 | kSpd300));
}

TEST(GoUntil, IgnoresTheTopFourBitsOfTheFirstSpdByte) {
  expect_same_effect(cmd3(0x82, kSpd300), cmd3(0x82, 0xA00000 | kSpd300));
}

TEST(Move, IgnoresTheTopTwoBitsOfTheFirstNStepByte) {
  expect_same_effect(cmd3(0x41, 500), cmd3(0x41, 0xC00000 | 500));
}

TEST(GoTo, IgnoresTheTopTwoBitsOfTheFirstPositionByte) {
  expect_same_effect(cmd3(0x60, 0x3FFF00), cmd3(0x60, 0xFFFF00));
}

TEST(GoToDir, IgnoresTheTopTwoBitsOfTheFirstPositionByte) {
  expect_same_effect(cmd3(0x69, 400), cmd3(0x69, 0x800000 | 400));
}

TEST(SetParam, IgnoresTheValueBitsAboveTheRegisterWidth) {
  expect_same_effect(set_param_bytes(0x07, 0x020, 2), set_param_bytes(0x07, 0xFC20, 2),
                     /*setup=*/{});
  expect_same_effect(set_param_bytes(0x11, 0x3, 1), set_param_bytes(0x11, 0xF3, 1));
}

}  // namespace
}  // namespace l6470emu
