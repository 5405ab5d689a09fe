// Decode (daisychain/decode.hpp, protocol_tracker.hpp, explain.hpp): every command and
// answer attributed to its chip, values in the datasheet's units, register names from the
// variant table in force, and the diagnostics for bytes a real chip would misread.
#include <gtest/gtest.h>

#include <sstream>

#include "daisychain/chain_spec.hpp"
#include "daisychain/decode.hpp"
#include "daisychain/explain.hpp"
#include "daisychain/recording_chain.hpp"
#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

struct Decoded {
  std::string log;
  DecodeSummary summary;
};

Decoded decode_text(const std::string& text, const std::string& chain_spec, DecodeOptions o = {}) {
  NativeTraceReader r(text, "t.trace");
  Chain chain = make_chain(parse_chain_spec(chain_spec));
  std::ostringstream out;
  Decoded d;
  d.summary = decode_trace(r, chain, out, o);
  d.log = out.str();
  return d;
}

/// A trace of one CS frame per line: "mosi bytes | miso bytes", frames 10 µs apart.
std::string frames(const std::vector<std::string>& lines) {
  std::string t = "l6470emu-trace 1\n";
  Tick tick = 4;
  for (const std::string& l : lines) {
    t += format_seconds(tick) + " frame 1.75us " + l + "\n";
    tick += 40;
  }
  return t;
}

TEST(Explain, PutsValuesInTheDatasheetsUnits) {
  const Variant& v = l6470();
  const StatusLayout& s = v.status;
  EXPECT_EQ(describe_command(0x05, 0x08A, v, s), "SetParam(ACC, 0x08A = 2008 step/s²)");
  EXPECT_EQ(describe_command(0x07, 0x041, v, s), "SetParam(MAX_SPEED, 0x041 = 991.8 step/s)");
  EXPECT_EQ(describe_command(0x08, 0x1000 | 0x0FF, v, s), "SetParam(MIN_SPEED, 0x10FF = 60.80 step/s, LSPD_OPT)");
  EXPECT_EQ(describe_command(0x15, 0x027, v, s), "SetParam(FS_SPD, 0x027 = 602.7 step/s)");
  EXPECT_EQ(describe_command(0x16, 0x07, v, s), "SetParam(STEP_MODE, 0x07 = STEP_SEL 7 (1/128 step))");
  EXPECT_EQ(describe_command(0x09, 0x29, v, s), "SetParam(KVAL_HOLD, 0x29 = 16.0 % of VS)");
  EXPECT_EQ(describe_command(0x41, 3200, v, s), "Move(FWD, 3200 microsteps)");
  EXPECT_EQ(describe_command(0x50, 0x04189, v, s), "Run(REV, SPD 0x04189 = 250.0 step/s)");
  EXPECT_EQ(describe_command(0x60, 0x3FFFFF, v, s), "GoTo(ABS_POS -1)");
  EXPECT_EQ(describe_command(0x8B, 0x04189, v, s), "GoUntil(ACT=1: ABS_POS to MARK, FWD, SPD 0x04189 = 250.0 step/s)");
  EXPECT_EQ(describe_command(0xB0, 0, v, s), "SoftStop");
  EXPECT_EQ(describe_answer(0xD0, 0x7E03, v, s), "GetStatus → 0x7E03 [HiZ REV STOPPED]");
  EXPECT_EQ(describe_answer(0x21, 0x3FFFF0, v, s), "GetParam(ABS_POS) → 0x3FFFF0 = -16 microsteps");
  EXPECT_EQ(opcode_name(0xEB, v), "RESERVED 0xEB");
  EXPECT_EQ(opcode_name(0x1A, v), "SetParam(0x1A, no such register)");
  EXPECT_EQ(opcode_name(0x52, v), "unknown opcode 0x52");
}

TEST(Explain, TakesRegisterNamesFromTheVariantTable) {
  // CONFIG and STATUS sit at 0x1A/0x1B on the L6480; 0x18 is GATECFG1 there.
  const Variant& v = *find_variant("L6480");
  EXPECT_EQ(opcode_name(0x3A, v), "GetParam(CONFIG)");
  EXPECT_EQ(opcode_name(0x38, v), "GetParam(GATECFG1)");
  EXPECT_EQ(opcode_name(0x38, l6470()), "GetParam(CONFIG)");
}

TEST(Decode, ExplainsCommandsAndAnswersPerChipWithTheirTimes) {
  const Decoded d = decode_text(frames({"D0 | 00", "00 | 7C", "00 | 03", "05 | 00", "00 | 00", "8A | 00", "D0 | 00",
                                        "00 | 7E", "00 | 03"}),
                                "1");
  EXPECT_EQ(d.log,
            "t=0.000001 s  chip 0   GetStatus → 0x7C03 [HiZ REV STOPPED UVLO]\n"
            "t=0.000051 s  chip 0   SetParam(ACC, 0x08A = 2008 step/s²)\n"
            "t=0.000061 s  chip 0   GetStatus → 0x7E03 [HiZ REV STOPPED]\n");
  EXPECT_EQ(d.summary.commands, 1u);
  EXPECT_EQ(d.summary.answers, 2u);
  EXPECT_EQ(d.summary.diagnostics, 0u);
}

TEST(Decode, AttributesTheBytesOfAChainToTheirChips) {
  // Chip 0 reads ABS_POS while chip 1 gets a Move and chip 2 a GetStatus (right-aligned).
  const Decoded d = decode_text(frames({"21 41 00 | 00 00 00", "00 00 00 | 00 00 00", "00 01 D0 | 00 00 00",
                                        "00 00 00 | 00 00 7C", "00 00 00 | 00 00 03"}),
                                "3*L6470");
  EXPECT_NE(d.log.find("chip 1   Move(FWD, 256 microsteps)"), std::string::npos) << d.log;
  EXPECT_NE(d.log.find("chip 0   GetParam(ABS_POS) → 0x000000 = 0 microsteps"), std::string::npos) << d.log;
  EXPECT_NE(d.log.find("chip 2   GetStatus → 0x7C03"), std::string::npos) << d.log;
}

TEST(Decode, ShowsOneChipWhenAsked) {
  DecodeOptions o;
  o.only_chip = 1;
  const Decoded d = decode_text(frames({"21 41 00 | 00 00 00", "00 00 00 | 00 00 00", "00 01 D0 | 00 00 00",
                                        "00 00 00 | 00 00 7C", "00 00 00 | 00 00 03"}),
                                "3*L6470", o);
  EXPECT_EQ(d.log, "t=0.000031 s  chip 1   Move(FWD, 256 microsteps)\n");
}

TEST(Decode, ReportsCommandsTheChipRefuses) {
  // Move, then SetParam(ACC) while it runs: NOTPERF_CMD (ACC is WS).
  const Decoded d = decode_text(frames({"41", "00", "10", "00", "05", "00", "20"}), "1");
  EXPECT_NE(d.log.find("chip 0   SetParam(ACC, 0x020 = 465.7 step/s²)\n"), std::string::npos) << d.log;
  EXPECT_NE(d.log.find("chip 0   ! NOTPERF_CMD: SetParam(ACC) refused (SetParam of ACC while the motor runs)  [t.trace:8]"),
            std::string::npos)
      << d.log;
}

TEST(Decode, ReportsBytesThatAreNoCommand) {
  const Decoded d = decode_text(frames({"EB", "1A", "52"}), "1");
  EXPECT_NE(d.log.find("! WRONG_CMD: RESERVED 0xEB (byte 0xEB: reserved opcode)"), std::string::npos) << d.log;
  EXPECT_NE(d.log.find("! WRONG_CMD: SetParam(0x1A, no such register) (byte 0x1A: no register at this address)"),
            std::string::npos)
      << d.log;
  EXPECT_NE(d.log.find("! WRONG_CMD: unknown opcode 0x52 (byte 0x52: no such command)"), std::string::npos) << d.log;
}

TEST(Decode, ExplainsCsHeldLowOverSeveralBytesToOneChip) {
  // A host that keeps CS low over a GetParam: the chip decodes only the last byte.
  const Decoded d = decode_text(frames({"21 00 00 00 | 00 21 00 00"}), "1");
  EXPECT_NE(d.log.find("frame 1 ! frame length: CS held low over 4 bytes for a single chip: only the last one (0x00) is "
                       "decoded, the others pass through (a real chip needs CS raised after every byte)"),
            std::string::npos)
      << d.log;
}

TEST(Decode, ExplainsFramesShorterThanTheChain) {
  const Decoded d = decode_text(frames({"D0 D0 D0 | 00 00 00", "00 00 | 7C 7C", "00 00 00 | 03 03 03"}), "3");
  EXPECT_NE(d.log.find("2 bytes for a chain of 3: chip 0 decodes a byte left in the chain, not host bytes (chip 0 "
                       "decodes 0x7C, the byte chip 2 left in the chain)"),
            std::string::npos)
      << d.log;
  // Chip 0 took the MSB of chip 2's STATUS for a command; it never reached MISO.
  EXPECT_NE(d.log.find("chip 0   ! WRONG_CMD: unknown opcode 0x7C (byte 0x7C: no such command); it is the byte chip 2 "
                       "left in the chain, not a host byte"),
            std::string::npos)
      << d.log;
  EXPECT_NE(d.log.find("chip 2   ! GetStatus answer lost: only 1 of 2 answer bytes reached MISO (frames too short to "
                       "clock them out)"),
            std::string::npos)
      << d.log;
}

TEST(Decode, ShowsTheEmulatorsAnswerWhereTheCaptureDiffers) {
  const Decoded d = decode_text(frames({"D0 | 00", "00 | 7E", "00 | 03"}), "1");
  EXPECT_NE(d.log.find("GetStatus → 0x7E03 [HiZ REV STOPPED]  (the emulator answers 0x7C03)"), std::string::npos) << d.log;
  EXPECT_EQ(d.summary.answer_mismatches, 1u);
}

TEST(Decode, ShowsPinsAndFaultsAndStandby) {
  const Decoded d = decode_text("l6470emu-trace 1\n0.001 pin 0 STBY 0\n0.002 frame D0 | 00\n0.003 fault 0 THERMAL warning\n",
                                "1");
  EXPECT_NE(d.log.find("t=0.001000 s  chip 0   STBY\\RST low (standby)"), std::string::npos) << d.log;
  EXPECT_NE(d.log.find("! standby: in standby (STBY\\RST low): ignores 0xD0"), std::string::npos) << d.log;
  EXPECT_NE(d.log.find("fault THERMAL warning"), std::string::npos) << d.log;
}

TEST(Decode, ShowsEachKindOfDiagnosticAFewTimesPerChip) {
  std::vector<std::string> lines(30, "EB");
  DecodeOptions o;
  o.max_repeats = 3;
  const Decoded d = decode_text(frames(lines), "1", o);
  EXPECT_EQ(d.summary.diagnostics, 30u);
  EXPECT_EQ(d.summary.suppressed, 27u);
  EXPECT_NE(d.log.find("(further ones of this kind not shown)"), std::string::npos);
}

TEST(Decode, ReadsTheRecordedFixtureWithoutSurprises) {
  const std::string text = test::fixture("three_chips.trace");
  NativeTraceReader r(text, "three_chips.trace");
  Chain chain = make_chain(parse_chain_spec(r.header().chain));
  std::ostringstream out;
  const DecodeSummary s = decode_trace(r, chain, out);
  EXPECT_EQ(s.answer_mismatches, 0u);
  const std::string log = out.str();
  EXPECT_NE(log.find("chip 0   GoUntil(ACT=0: reset ABS_POS, REV, SPD 0x04189 = 250.0 step/s)"), std::string::npos) << log;
  EXPECT_NE(log.find("chip 0   SW pin low (switch closed)"), std::string::npos) << log;
  EXPECT_NE(log.find("chip 2   GetStatus → 0x7A30 [BUSY FWD ACC TH_WRN]"), std::string::npos) << log;
}

}  // namespace
}  // namespace l6470emu

namespace l6470emu {
namespace {

/// A Move of 200 full steps recorded with RecordingChain; BUSY's release is observed `late`
/// ticks after the emulated edge (0: at the edge's own tick, as when a program waits on the line).
std::string move_recorded(Tick late) {
  Chain chain(1);
  Trace trace;
  RecordingChain rec(chain, trace);
  const auto send = [&](std::uint8_t b) {
    chain.advance_to(chain.now() + 40);
    rec.select();
    rec.exchange(b);
    chain.advance_to(chain.now() + 7);
    rec.deselect();
  };
  for (std::uint8_t b : {0x16, 0x00}) send(b);  // full steps
  for (std::uint8_t b : {0x41, 0x00, 0x00, 0xC8}) send(b);  // Move(FWD, 200)
  Tick lo = chain.now(), hi = lo + 4'000'000;  // busy at lo, released by hi
  while (hi - lo > 1) {
    const Tick mid = lo + (hi - lo) / 2;
    Chip probe = chain.chip(0);
    probe.advance_to(mid);
    (probe.busy_sync_pin() ? hi : lo) = mid;
  }
  chain.advance_to(hi + late);
  rec.observe_outputs();
  return to_native_text(trace);
}

TEST(DecodeOutputs, AnEdgeRecordedAtItsOwnTickIsShownAsTheEdge) {
  const std::string log = decode_text(move_recorded(0), "1").log;
  EXPECT_NE(log.find("BUSY output low (busy)\n"), std::string::npos) << log;  // at the Move's CS rising edge
  EXPECT_NE(log.find("BUSY output high (released)\n"), std::string::npos) << log;
  EXPECT_EQ(log.find("not watched"), std::string::npos) << log;
}

TEST(DecodeOutputs, AnEdgeObservedLaterSaysWhenTheEmulatorsCame) {
  const std::string log = decode_text(move_recorded(4000), "1").log;  // 1 ms late
  const auto at = log.find("BUSY output high (released), seen at (the edge was not watched: the emulator's came at t=");
  ASSERT_NE(at, std::string::npos) << log;
  EXPECT_NE(log.find("BUSY output low (busy)\n"), std::string::npos) << log;
}

TEST(DecodeOutputs, MarksBusyAndFlagLevelsAsSeenAtNotAsExactEdges) {
  const std::string text =
      "l6470emu-trace 1\n"
      "0.00000000 pin 0 BUSY 1\n"
      "0.00000000 pin 0 FLAG 0\n"
      "0.00000200 frame 1.75us D0 | 00\n"
      "0.00000550 pin 0 FLAG 1\n"
      "0.00010000 pin 0 SW 0\n"
      "0.00020000 pin 0 BUSY 0\n";
  const std::string log = decode_text(text, "1").log;
  EXPECT_NE(log.find("t=0.000000 s  chip 0   BUSY output high (released), seen at (its level when watching began)"),
            std::string::npos)
      << log;
  // The FLAG edge came after the frame's CS rising edge (3.75 µs), the BUSY edge after the SW event.
  EXPECT_NE(log.find("t=0.000005 s  chip 0   FLAG output high (no alarm), seen at (the edge was not watched: the "
                     "emulator's came at t=0.000004 s)"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("BUSY output low (busy), seen at (the edge was not watched: it came after t=0.000100 s)"),
            std::string::npos)
      << log;
}

}  // namespace
}  // namespace l6470emu

namespace l6470emu {
namespace {

/// The chip numbers of the lines of `log` that start with `stamp`, in order.
std::string chips_at(const std::string& log, const std::string& stamp) {
  std::string order;
  std::istringstream in(log);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(stamp, 0) == 0) order += line.substr(stamp.size() + 7, 1);  // "  chip N"
  return order;
}

TEST(DecodeOrder, ListsTheLinesOfOneTimeInTheUsersChipOrder) {
  // Each chip's BUSY is looked at together, then one frame gives each chip a SoftStop.
  const std::string text =
      "l6470emu-trace 1\n"
      "0.00000000 pin 0 BUSY 1\n"
      "0.00000000 pin 1 BUSY 1\n"
      "0.00000000 pin 2 BUSY 1\n"
      "0.00001500 frame 5.75us B0 B0 B0 | 00 00 00\n";
  const std::string miso = decode_text(text, "3").log;
  EXPECT_EQ(chips_at(miso, "t=0.000000 s"), "012") << miso;
  EXPECT_EQ(chips_at(miso, "t=0.000015 s"), "012") << miso;
  DecodeOptions o;
  o.number_from = NumberFrom::mosi;
  // Counted from the MOSI end, the chain's chip 2 is chip 0: it is listed first all the same.
  const std::string mosi = decode_text(text, "3", o).log;
  EXPECT_EQ(chips_at(mosi, "t=0.000000 s"), "012") << mosi;
  EXPECT_EQ(chips_at(mosi, "t=0.000015 s"), "012") << mosi;
}

}  // namespace
}  // namespace l6470emu
