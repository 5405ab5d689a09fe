// Both settings of every switchable quirk (core/quirks.hpp, docs/quirks.md): SetParam of a
// read-only register, and the write condition of INT_SPEED/ST_SLP/FN_SLP_ACC/FN_SLP_DEC/CONFIG.
#include <gtest/gtest.h>

#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "core/chip.hpp"
#include "core/quirks.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;


const std::uint32_t kSpd300 = test::spd_from_steps_per_s(300);

std::string hex(unsigned v) {
  std::ostringstream s;
  s << "0x" << std::hex << std::uppercase << v;
  return s.str();
}

/// One chip with the given quirks, and a host talking to it one byte per frame.
struct Rig {
  explicit Rig(Quirks q) : chain(1, l6470(), q), host(chain) {}
  Chain chain;
  ChainHost host;
  Chip& chip() { return chain.chip(0); }
  std::vector<std::uint8_t> send(std::vector<std::uint8_t> bytes) { return host.send(0, bytes); }
  /// Sends one byte per frame and records (WRONG_CMD, NOTPERF_CMD) after each.
  std::vector<std::pair<bool, bool>> flags_after_each(const std::vector<std::uint8_t>& bytes) {
    std::vector<std::pair<bool, bool>> out;
    for (auto b : bytes) {
      send({b});
      const auto s = chip().status();
      out.emplace_back((s & kWrongCmd) != 0, (s & kNotPerf) != 0);
    }
    return out;
  }
};

Quirks read_only_as(ReadOnlyWrite r) {
  Quirks q;
  q.read_only_write = r;
  return q;
}

Quirks bemf_as(BemfWriteCondition c) {
  Quirks q;
  q.bemf_write = c;
  return q;
}

std::vector<std::uint8_t> cmd3(std::uint8_t opcode, std::uint32_t arg) {
  return {opcode, static_cast<std::uint8_t>(arg >> 16), static_cast<std::uint8_t>(arg >> 8),
          static_cast<std::uint8_t>(arg)};
}

struct ReadOnly {
  std::uint8_t address;
  Reg id;
  unsigned bytes;
};
const ReadOnly kReadOnly[] = {{0x04, Reg::SPEED, 3}, {0x12, Reg::ADC_OUT, 1}, {0x19, Reg::STATUS, 2}};

TEST(Quirks, DefaultToTheRecommendedReadings) {
  const Quirks q;
  EXPECT_EQ(q.read_only_write, ReadOnlyWrite::wrong_cmd_at_command_byte);
  EXPECT_EQ(q.bemf_write, BemfWriteCondition::when_hiz);
  Chip chip;
  EXPECT_EQ(chip.quirks().read_only_write, ReadOnlyWrite::wrong_cmd_at_command_byte);
  EXPECT_EQ(chip.quirks().bemf_write, BemfWriteCondition::when_hiz);
  Chain chain(2, l6470(), read_only_as(ReadOnlyWrite::notperf_after_value));
  EXPECT_EQ(chain.chip(1).quirks().read_only_write, ReadOnlyWrite::notperf_after_value);
}

// ---------------------------------------------------------------- read_only_write

TEST(ReadOnlyWriteQuirk, ByDefaultRaisesWrongCmdAtTheCommandByteAndDecodesTheValueBytesAsCommands) {
  for (const auto& r : kReadOnly) {
    SCOPED_TRACE(hex(r.address));
    Rig rig(Quirks{});
    rig.chip().set_adc_input(3);
    const auto flags = rig.flags_after_each({r.address});
    EXPECT_EQ(flags.front(), std::make_pair(true, false)) << "WRONG_CMD at the command byte";
    // What would have been the value bytes are commands: SetParam(KVAL_RUN, 0x44).
    rig.send({0x0A, 0x44});
    EXPECT_EQ(rig.chip().peek(Reg::KVAL_RUN), 0x44u);
    EXPECT_EQ(rig.chip().status() & kNotPerf, 0);
    EXPECT_EQ(rig.chip().peek(Reg::ADC_OUT), 3u);
  }
}

TEST(ReadOnlyWriteQuirk, ByDefaultLeavesTheReadOnlyValueAlone) {
  Rig rig(Quirks{});
  rig.send({0x04, 0x00, 0x12, 0x35});  // 0x00 NOP, 0x12 SetParam(ADC_OUT) again, 0x35 GetParam(FS_SPD)
  EXPECT_EQ(rig.chip().peek(Reg::SPEED), 0u);
  EXPECT_EQ(rig.chip().peek(Reg::ADC_OUT), 0u);
  // 0x35 = GetParam(FS_SPD): its answer 0x0027 comes next.
  EXPECT_EQ(rig.send({0x00, 0x00}), (std::vector<std::uint8_t>{0x00, 0x27}));
}

TEST(ReadOnlyWriteQuirk, NotPerfAfterValueConsumesTheValueBytesThenRaisesNotPerf) {
  for (const auto& r : kReadOnly) {
    SCOPED_TRACE(hex(r.address));
    Rig rig(read_only_as(ReadOnlyWrite::notperf_after_value));
    rig.chip().set_adc_input(3);
    std::vector<std::uint8_t> tx{r.address};
    // Value bytes that would change KVAL_RUN if they were decoded as commands.
    const std::uint8_t value[] = {0x0A, 0x44, 0x0A};
    for (unsigned i = 0; i < r.bytes; ++i) tx.push_back(value[i]);
    const auto flags = rig.flags_after_each(tx);
    for (std::size_t i = 0; i + 1 < flags.size(); ++i)
      EXPECT_EQ(flags[i], std::make_pair(false, false)) << "byte " << i;
    EXPECT_EQ(flags.back(), std::make_pair(false, true)) << "NOTPERF_CMD at the last value byte";
    EXPECT_EQ(rig.chip().peek(Reg::KVAL_RUN), 0x29u) << "value bytes were not commands";
    EXPECT_EQ(rig.chip().peek(Reg::SPEED), 0u);
    EXPECT_EQ(rig.chip().peek(Reg::ADC_OUT), 3u);
    // The next byte is a command again.
    EXPECT_EQ(rig.send({0x29, 0x00}), (std::vector<std::uint8_t>{0x00, 0x29}));
  }
}

TEST(ReadOnlyWriteQuirk, DoesNotChangeWritesToWritableRegisters) {
  for (auto q : {ReadOnlyWrite::wrong_cmd_at_command_byte, ReadOnlyWrite::notperf_after_value}) {
    Rig rig(read_only_as(q));
    rig.send({0x07, 0x00, 0x30});
    EXPECT_EQ(rig.chip().peek(Reg::MAX_SPEED), 0x30u);
    EXPECT_EQ(rig.chip().status() & (kNotPerf | kWrongCmd), 0);
  }
}

TEST(ReadOnlyWriteQuirk, DoesNotChangeMissingAddressesWhichAlwaysRaiseWrongCmd) {
  Rig rig(read_only_as(ReadOnlyWrite::notperf_after_value));
  rig.send({0x1A});
  EXPECT_NE(rig.chip().status() & kWrongCmd, 0);
  rig.send({0x0A, 0x44});
  EXPECT_EQ(rig.chip().peek(Reg::KVAL_RUN), 0x44u);
}

// ---------------------------------------------------------------- bemf_write

struct Bemf {
  std::uint8_t address;
  Reg id;
  unsigned bytes;
  std::uint32_t value;
};
const Bemf kBemf[] = {{0x0D, Reg::INT_SPEED, 2, 0x1234},
                      {0x0E, Reg::ST_SLP, 1, 0x55},
                      {0x0F, Reg::FN_SLP_ACC, 1, 0x56},
                      {0x10, Reg::FN_SLP_DEC, 1, 0x57},
                      {0x18, Reg::CONFIG, 2, 0x2E98}};

std::vector<std::uint8_t> set_param_bytes(std::uint8_t address, std::uint32_t value, unsigned bytes) {
  std::vector<std::uint8_t> tx{address};
  for (unsigned i = bytes; i-- > 0;) tx.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
  return tx;
}

enum class State { hiz_stopped, enabled_stopped, running };

/// Whether a write of `b` was accepted with the quirk `c` in state `st`; checks the flag timing too.
bool write_accepted(BemfWriteCondition c, State st, const Bemf& b) {
  Rig rig(bemf_as(c));
  if (st == State::enabled_stopped) rig.send({0xB8});
  if (st == State::running) {
    rig.send(cmd3(0x51, kSpd300));
    rig.host.wait_ms(20);
  }
  rig.send({0xD0, 0x00, 0x00});  // clear the flags
  const auto before = rig.chip().peek(b.id);
  const auto tx = set_param_bytes(b.address, b.value, b.bytes);
  const auto flags = rig.flags_after_each(tx);
  for (std::size_t i = 0; i + 1 < flags.size(); ++i) EXPECT_FALSE(flags[i].second) << "byte " << i;
  EXPECT_FALSE(flags.back().first) << "never WRONG_CMD";
  const bool refused = flags.back().second;
  EXPECT_EQ(rig.chip().peek(b.id), refused ? before : b.value);
  return !refused;
}

TEST(BemfWriteQuirk, WhenHiZAcceptsTheWriteOnlyWithTheBridgesInHiZ) {
  for (const auto& b : kBemf) {
    SCOPED_TRACE(hex(b.address));
    EXPECT_TRUE(write_accepted(BemfWriteCondition::when_hiz, State::hiz_stopped, b));
    EXPECT_FALSE(write_accepted(BemfWriteCondition::when_hiz, State::enabled_stopped, b));
    EXPECT_FALSE(write_accepted(BemfWriteCondition::when_hiz, State::running, b));
  }
}

TEST(BemfWriteQuirk, WhenStoppedAcceptsTheWriteWheneverTheMotorIsStopped) {
  for (const auto& b : kBemf) {
    SCOPED_TRACE(hex(b.address));
    EXPECT_TRUE(write_accepted(BemfWriteCondition::when_stopped, State::hiz_stopped, b));
    EXPECT_TRUE(write_accepted(BemfWriteCondition::when_stopped, State::enabled_stopped, b));
    EXPECT_FALSE(write_accepted(BemfWriteCondition::when_stopped, State::running, b));
  }
}

TEST(BemfWriteQuirk, WhenStoppedStillLeavesStepModeWritableOnlyInHiZ) {
  // STEP_MODE is WH in the table and in the text (spec §2.1 notes, §3.5): not part of the conflict.
  const Bemf step_mode{0x16, Reg::STEP_MODE, 1, 0x03};
  EXPECT_TRUE(write_accepted(BemfWriteCondition::when_stopped, State::hiz_stopped, step_mode));
  EXPECT_FALSE(write_accepted(BemfWriteCondition::when_stopped, State::enabled_stopped, step_mode));
}

TEST(BemfWriteQuirk, WhenStoppedAcceptsTheWriteInStepClockMode) {
  Rig rig(bemf_as(BemfWriteCondition::when_stopped));
  rig.send({0x59});
  ASSERT_FALSE(rig.chip().hiz());
  rig.send(set_param_bytes(0x0E, 0x42, 1));
  EXPECT_EQ(rig.chip().peek(Reg::ST_SLP), 0x42u);
  EXPECT_EQ(rig.chip().status() & kNotPerf, 0);
}

}  // namespace
}  // namespace l6470emu
