// The driver sanitizer on the OS-free Board, as every front sees it: a front that times its own
// chip-select (CS_DESELECT_TIME, CS_SETUP_TIME, which spidev cannot produce), the settings a
// front passes (SPISettings, HAL's CLKPolarity/CLKPhase/FirstBit), frames and messages, the
// chips' diagnostics, and the levels: off, warn (rate-limited lines), error (one report).
#include <gtest/gtest.h>

#include <array>
#include <span>
#include <string>
#include <vector>

#include "board/board.hpp"
#include "spi/message.hpp"
#include "support/board_config_support.hpp"

namespace l6470emu::test {
namespace {

class StillHostClock final : public HostClock {
 public:
  std::int64_t monotonic_ns() override { return 0; }
  std::int64_t realtime_ns() override { return 0; }
  void sleep_until(std::int64_t) override {}
};

struct VirtualBoard {
  explicit VirtualBoard(const std::string& description)
      : board(config_of(description + "; time=virtual"), [this](std::string_view line) { log.emplace_back(line); },
              clock) {}
  StillHostClock clock;
  std::vector<std::string> log;
  Board board;

  std::string failure() { return board.take_check_failure().value_or(""); }
};

/// A firmware-style front: CS on a pin it writes, SPI.transfer one byte at a time with the
/// settings of its beginTransaction, its own time between the calls.
struct Front {
  Board& board;
  WireSettings wire;
  explicit Front(Board& b, WireSettings w = {}) : board(b), wire(w) {
    wire.cs_setup_timed = true;  // the front drives CS itself: its ticks are the real ones
    if (wire.speed_hz == 0) wire.speed_hz = 4'000'000;
  }
  void cs(bool low) {
    SpiDevice& dev = board.begin_transfer(0, wire);
    low ? dev.select() : dev.deselect();
    board.advance_to(board.end_transfer(0));
  }
  std::uint8_t transfer(std::uint8_t mosi) {
    SpiDevice& dev = board.begin_transfer(0, wire);
    dev.advance_to(dev.now() + transfer_ticks(1, wire.speed_hz));
    std::uint8_t miso = 0;
    dev.exchange_wire({&mosi, 1}, {&miso, 1}, wire);
    board.advance_to(board.end_transfer(0));
    return miso;
  }
  void wait(Tick ticks) { board.advance(ticks); }
  /// One byte in its own CS frame, then CS high for `high` ticks, `setup` ticks between CS
  /// falling and the first clock.
  std::uint8_t frame(std::uint8_t mosi, Tick high = 4, Tick setup = 2) {
    cs(true);
    wait(setup);
    const std::uint8_t miso = transfer(mosi);
    cs(false);
    wait(high);
    return miso;
  }
};

TEST(SanitizerBoard, ADeselectShorterThanTDisCSIsNamedAndTheChipsMissTheirAnswerLoad) {
  VirtualBoard v("chips=L6470 check=error");
  Front f(v.board);
  f.frame(0x38, /*high=*/3);  // GetParam(CONFIG), then CS high for 750 ns
  EXPECT_EQ(f.frame(0x00), 0x38);  // the answer was not loaded: the opcode comes back
  const std::string report = v.failure();
  EXPECT_NE(report.find("driver sanitizer: CS_DESELECT_TIME on spidev0.0, chip 0, frame 2 (t="), std::string::npos)
      << report;
  EXPECT_NE(report.find("CS was high for 750 ns before this frame (t_disCS is at least 800 ns)"), std::string::npos)
      << report;
  EXPECT_NE(report.find("datasheet: Table 5 \"SPI\": t_disCS >= 800 ns"), std::string::npos) << report;
  // 1 µs is enough.
  f.frame(0x38, 4);
  EXPECT_EQ(f.frame(0x00), 0x2E);
  EXPECT_EQ(v.failure(), "");
}

TEST(SanitizerBoard, AFirstClockEdgeSoonerThanTSetCSIsNamed) {
  VirtualBoard v("chips=L6470 check=error");
  Front f(v.board);
  f.frame(0x00, 4, /*setup=*/2);  // 500 ns: fine
  EXPECT_EQ(v.failure(), "");
  f.frame(0x00, 4, /*setup=*/1);  // 250 ns
  const std::string report = v.failure();
  EXPECT_NE(report.find("CS_SETUP_TIME on spidev0.0, chip 0, frame 2, byte 0"), std::string::npos) << report;
  EXPECT_NE(report.find("the first clock edge came 250 ns after CS fell (t_setCS is at least 350 ns)"), std::string::npos)
      << report;
  // spidev's controller's own CS-to-clock delay is not known: not checked.
  Front untimed(v.board);
  untimed.wire.cs_setup_timed = false;
  untimed.frame(0x00, 4, 0);
  EXPECT_EQ(v.failure(), "");
}

TEST(SanitizerBoard, TheSettingsAFrontPassesAreCheckedAndServedAsTheWireGivesThem) {
  VirtualBoard v("chips=L6470 check=warn");
  WireSettings mode0;
  mode0.mode = 0;
  mode0.speed_hz = 8'000'000;
  Front f(v.board, mode0);
  f.frame(0x00);
  f.frame(0x38);
  EXPECT_EQ(f.frame(0x00), 0x2E);
  EXPECT_EQ(f.frame(0x00), 0x08);  // CONFIG 0x2E88 in mode 0
  ASSERT_EQ(v.log.size(), 2u);     // each setting once
  EXPECT_EQ(v.log[0].rfind("spidev0.0: chip 0: SPI_MODE: the host clocks in SPI mode 0 (CPOL=0, CPHA=0)", 0), 0u)
      << v.log[0];
  EXPECT_EQ(v.log[1],
            "spidev0.0: chip 0: SCK_SPEED: SCK is 8 MHz; the chip is specified up to 5 MHz (the emulator serves it as if "
            "it worked) (frame 1, byte 0)");
  // Another mode is another problem.
  f.wire.mode = 1;
  f.frame(0x00);
  ASSERT_EQ(v.log.size(), 3u);
  EXPECT_NE(v.log[2].find("SPI_MODE: the host clocks in SPI mode 1 (CPOL=0, CPHA=1)"), std::string::npos) << v.log[2];
  EXPECT_NE(v.log[2].find("MOSI reaches the chips one bit late"), std::string::npos) << v.log[2];
}

TEST(SanitizerBoard, CsActiveHighReachesNothingAndIsNamed) {
  VirtualBoard v("chips=L6470 check=error");
  WireSettings high;
  high.cs_active_high = true;
  Front f(v.board, high);
  EXPECT_EQ(f.frame(0xD0), 0x00);
  const std::string report = v.failure();
  EXPECT_NE(report.find("CS_ACTIVE_HIGH on spidev0.0, chip 0"), std::string::npos) << report;
  EXPECT_NE(report.find("never selected: no byte reaches it and MISO reads 0x00"), std::string::npos) << report;
  EXPECT_EQ(v.board.chain(0).peek_chip(0).collecting_arguments(), false);
}

TEST(SanitizerBoard, FramesThatAreNotTheChainsLengthAreNamedWithTheirEffect) {
  VirtualBoard v("chips=3xL6470 check=warn");
  const std::uint8_t two[2] = {0xD0, 0xD0}, six[6] = {};
  const std::uint8_t four[4] = {0x00, 0xD0, 0xD0, 0xD0};
  auto message = [&](std::span<const std::uint8_t> tx) {
    SpiTransfer t;
    t.tx = tx;
    t.len = static_cast<std::uint32_t>(tx.size());
    v.board.transfer(0, std::span<const SpiTransfer>(&t, 1));
  };
  message(two);
  message(six);
  message(four);
  ASSERT_EQ(v.log.size(), 3u);
  EXPECT_EQ(v.log[0],
            "spidev0.0: every chip: FRAME_LENGTH: 2 bytes in a frame for a chain of 3: chip 0 decodes a byte left in the "
            "chain, not the host's, and the host's bytes land in chips they were not meant for (frame 1)");
  EXPECT_EQ(v.log[1],
            "spidev0.0: every chip: FRAME_PASS_THROUGH: 6 bytes in a frame for a chain of 3: MOSI bytes 0..2 pass "
            "through the chain undecoded (CS must rise after every 3 bytes) (frame 2)");
  EXPECT_EQ(v.log[2],
            "spidev0.0: every chip: FRAME_LENGTH: 4 bytes in a frame for a chain of 3: MOSI bytes 0..0 pass through "
            "undecoded and chip k decodes MOSI byte 1+k: the host's bytes land in chips they were not meant for (frame 3)");
}

TEST(SanitizerBoard, AMessageThatLeavesOneChipMidCommandWhileAnotherFinishedIsNamed) {
  VirtualBoard v("chips=2xL6470 numbering=mosi check=error");
  const std::uint8_t tx[4] = {0xD0, 0x41, 0x00, 0x00};  // GetStatus to chip 0 (MISO end), Move to chip 1
  SpiTransfer t[2];
  for (int i = 0; i < 2; ++i) {
    t[i].tx = std::span<const std::uint8_t>(tx + 2 * i, 2);
    t[i].len = 2;
    t[i].cs_change = i == 0;
  }
  v.board.transfer(0, t);
  const std::string report = v.failure();
  // numbering=mosi: the chain's chip 1 is the user's chip 0.
  EXPECT_NE(report.find("COMMAND_SPLIT on spidev0.0, chip 0, frame 2 (t="), std::string::npos) << report;
  EXPECT_NE(report.find("waits for 2 argument bytes of Move and chip 1 has finished its command"), std::string::npos)
      << report;
  // The same bytes as one frame per message are a chain host's everyday business.
  VirtualBoard w("chips=2xL6470 check=error");
  t[0].cs_change = false;
  for (int i = 0; i < 2; ++i) w.board.transfer(0, std::span<const SpiTransfer>(&t[i], 1));
  EXPECT_EQ(w.failure(), "");
}

TEST(SanitizerBoard, TheChipsDiagnosticsNameTheChipTheFrameAndTheByteTheyDecoded) {
  VirtualBoard v("chips=3xL6470 numbering=mosi check=warn");
  const std::uint8_t tx[3] = {0x00, 0xE5, 0x00};  // the chain's chip 1 gets 0xE5
  SpiTransfer t;
  t.tx = tx;
  t.len = 3;
  v.board.transfer(0, std::span<const SpiTransfer>(&t, 1));
  ASSERT_EQ(v.log.size(), 1u);
  EXPECT_EQ(v.log[0], "spidev0.0: chip 1: WRONG_CMD: byte 0xE5: no such command (frame 1, byte 1)");
}

TEST(SanitizerBoard, ErrorKeepsOnlyTheFirstBrokenRuleUntilTheFrontTakesIt) {
  VirtualBoard v("chips=L6470 check=error");
  Front f(v.board);
  f.frame(0xE5);
  f.frame(0xEB);
  EXPECT_TRUE(v.board.sanitizer().failed());
  const std::string report = v.failure();
  EXPECT_NE(report.find("byte 0xE5"), std::string::npos) << report;
  EXPECT_EQ(report.find("0xEB"), std::string::npos) << report;
  EXPECT_FALSE(v.board.sanitizer().failed());
  EXPECT_TRUE(v.log.empty());  // the front reports the failure, not the log
}

TEST(SanitizerBoard, WarnShowsEachRuleTenTimesPerChipThenCounts) {
  VirtualBoard v("chips=L6470");  // warn is the default
  Front f(v.board);
  for (int i = 0; i < 1000; ++i) f.frame(0xE5);
  ASSERT_EQ(v.log.size(), 12u);
  EXPECT_NE(v.log[9].find("(further ones of this kind are counted, not shown)"), std::string::npos) << v.log[9];
  EXPECT_EQ(v.log[10], "spidev0.0: chip 0: WRONG_CMD: 100 so far");
  EXPECT_EQ(v.log[11], "spidev0.0: chip 0: WRONG_CMD: 1000 so far");
}

TEST(SanitizerBoard, OffAndAllowedRulesSayNothingAndChangeNothingTheChipsDo) {
  VirtualBoard off("chips=L6470 check=off");
  VirtualBoard allowed("chips=L6470 check=error check.allow=WRONG_CMD,UNUSED_BITS");
  for (VirtualBoard* v : {&off, &allowed}) {
    Front f(v->board);
    f.frame(0xE5);
    f.frame(0x07);  // SetParam(MAX_SPEED) = 0x0400: 11 bits into a 10-bit register
    f.frame(0x04);
    f.frame(0x00);
    f.frame(0xD0);
    EXPECT_EQ(f.frame(0x00), 0x7D);  // 0x7D03: WRONG_CMD latched (and UVLO), as the chip does
    EXPECT_TRUE(v->log.empty());
    EXPECT_EQ(v->failure(), "");
    v->board.with_chain(0, [](Chain& c) { EXPECT_EQ(c.chip(0).peek(Reg::MAX_SPEED), 0u); });
  }
  allowed.board.sanitizer().set_config({CheckLevel::error, {}});
  Front f(allowed.board);
  f.frame(0x00);
  f.frame(0xE5);
  EXPECT_NE(allowed.failure().find("WRONG_CMD"), std::string::npos);
}

TEST(SanitizerBoard, ASignExtendedPositionHasNoUnusedBitsButAnOversizedMoveHas) {
  VirtualBoard v("chips=L6470 check=warn");
  Front f(v.board);
  for (std::uint8_t b : {0x01, 0xFF, 0xFF, 0x9C}) f.frame(b);  // SetParam(ABS_POS, -100), sign-extended to 24 bits
  for (std::uint8_t b : {0x60, 0xFF, 0xFF, 0x9C}) f.frame(b);  // GoTo(-100)
  EXPECT_TRUE(v.log.empty()) << v.log.front();
  for (std::uint8_t b : {0xB8}) f.frame(b);                    // HardStop
  for (std::uint8_t b : {0x41, 0x40, 0x00, 0x00}) f.frame(b);  // Move(FWD, 0x400000): 23 bits
  ASSERT_EQ(v.log.size(), 1u);
  EXPECT_EQ(v.log[0].rfind("spidev0.0: chip 0: UNUSED_BITS: Move value 0x400000 has bits above the 22 N_STEP has "
                           "(0x400000): the chip keeps 0x000000",
                           0),
            0u)
      << v.log[0];
}

TEST(SanitizerBoard, AReservedBitWrittenOneIsNamedWhereTheVariantReservesItAndNowhereElse) {
  // STEP_MODE bit 3: written 0 on the L6470 and L6480; CM_VM on the powerSTEP01; on the L6482
  // the sources conflict (cSPIN says 1, its defaults 0), so nothing is said. CONFIG bit 6 everywhere.
  for (const char* chips : {"L6470", "L6480", "L6482", "powerSTEP01"}) {
    VirtualBoard v(std::string("chips=") + chips + " check=warn");
    Front f(v.board);
    for (std::uint8_t b : {0x16, 0x0F}) f.frame(b);  // SetParam(STEP_MODE, 1/128 with bit 3 set)
    const bool named = std::string(chips) == "L6470" || std::string(chips) == "L6480";
    ASSERT_EQ(v.log.size(), named ? 1u : 0u) << chips << ": " << (v.log.empty() ? "" : v.log[0]);
    if (named) {
      EXPECT_EQ(v.log[0].rfind("spidev0.0: chip 0: RESERVED_BITS: SetParam(STEP_MODE) value 0x0F sets bit 3, which is "
                               "to be written 0: ",
                               0),
                0u)
          << v.log[0];
    }
    v.log.clear();
    const std::uint8_t config = std::string(chips) == "L6470" ? 0x18 : 0x1A;
    for (std::uint8_t b : {config, std::uint8_t{0x2E}, std::uint8_t{0xC8}}) f.frame(b);  // 0x2E88 with bit 6 set
    ASSERT_EQ(v.log.size(), 1u) << chips;
    EXPECT_NE(v.log[0].find("RESERVED_BITS: SetParam(CONFIG) value 0x2EC8 sets bit 6"), std::string::npos) << v.log[0];
    v.log.clear();
    for (std::uint8_t b : {config, std::uint8_t{0x2E}, std::uint8_t{0x88}}) f.frame(b);  // the reset value: fine
    EXPECT_TRUE(v.log.empty()) << chips << ": " << v.log.front();
  }
}

TEST(SanitizerBoard, TheReportHasEverythingOnItsLinesAndTheRuleTableIsComplete) {
  const std::string report = violation_report({Rule::WRONG_CMD, "spidev0.0", "chip 2", "2", 7, 1, 4000, "byte 0xE5"});
  EXPECT_EQ(report,
            "l6470emu: driver sanitizer: WRONG_CMD on spidev0.0, chip 2, frame 7, byte 1 (t=0.001000 s)\n"
            "  what:      byte 0xE5\n"
            "  rule:      a byte that is no command, or SetParam/GetParam of a register the chip lacks\n"
            "  datasheet: §9.2.1 Command management (last paragraph), §9.2.3 SetParam; STATUS WRONG_CMD, §9.1.22 Table 34\n"
            "  (check=error: the run ends here. To allow this rule: check.allow=WRONG_CMD in the board description, "
            "L6470EMU_CHECK_ALLOW=WRONG_CMD, or check_allow=[\"WRONG_CMD\"] in Python)\n");
  for (std::size_t i = 0; i < kRuleCount; ++i) {
    const RuleInfo& r = rule_table()[i];
    EXPECT_EQ(static_cast<std::size_t>(r.rule), i);
    EXPECT_EQ(rule_named(r.name), r.rule);
    EXPECT_FALSE(r.about.empty());
    EXPECT_FALSE(r.datasheet.empty());
    EXPECT_TRUE(r.mark.starts_with("CONFIRMED") || r.mark.starts_with("UNCONFIRMED")) << r.name << ": " << r.mark;
  }
}

/// The firmware fronts' own path: CS on a pin (Board::drive_chip_select) and bytes clocked on a
/// bus with a controller's settings (Board::clock_bytes), as SPI.transfer and HAL_SPI_* do.
struct PinFront {
  Board& board;
  BusSettings settings;
  std::array<std::size_t, 1> bus{0};
  void cs(bool low) { board.drive_chip_select(0, low); }
  std::uint8_t transfer(std::uint8_t mosi) {
    std::uint8_t miso = 0;
    board.advance_to(board.clock_bytes(bus, std::span(&mosi, 1), std::span(&miso, 1), settings));
    return miso;
  }
  std::uint8_t frame(std::uint8_t mosi, Tick high = 4, Tick setup = 2) {
    cs(true);
    board.advance(setup);
    const std::uint8_t miso = transfer(mosi);
    cs(false);
    board.advance(high);
    return miso;
  }
};

TEST(SanitizerPinFront, AMode0ControllerReadsTheStaleLatchAndIsNamed) {
  VirtualBoard v("chips=L6470 check=warn");
  PinFront f{v.board, BusSettings{4'000'000, 0, false}};
  f.frame(0x00);
  f.frame(0x38);
  EXPECT_EQ(f.frame(0x00) << 8 | f.frame(0x00), 0x2E08) << "CONFIG 0x2E88 as a mode-0 host reads it on silicon";
  ASSERT_EQ(v.log.size(), 1u);
  EXPECT_EQ(v.log[0].rfind("spidev0.0: chip 0: SPI_MODE: the host clocks in SPI mode 0 (CPOL=0, CPHA=0)", 0), 0u)
      << v.log[0];
  // Mode 3 on the same path: the register as it is, and nothing said.
  f.settings.mode = 3;
  f.frame(0x38);
  EXPECT_EQ(f.frame(0x00) << 8 | f.frame(0x00), 0x2E88);
  EXPECT_EQ(v.log.size(), 1u);
}

TEST(SanitizerPinFront, ACsPulseShorterThanTDisCSEchoesTheByteAndEndsACheckErrorRun) {
  VirtualBoard v("chips=L6470 check=error");
  PinFront f{v.board, BusSettings{4'000'000, 3, false}};
  f.frame(0x38, /*high=*/2);       // GetParam(CONFIG), then CS high for 500 ns
  EXPECT_EQ(f.frame(0x00), 0x38);  // no answer load: the opcode comes back
  const std::string report = v.failure();
  EXPECT_NE(report.find("driver sanitizer: CS_DESELECT_TIME on spidev0.0, chip 0, frame 2"), std::string::npos) << report;
  EXPECT_NE(report.find("CS was high for 500 ns before this frame"), std::string::npos) << report;
  f.frame(0x00, 4, /*setup=*/1);   // a first clock 250 ns after CS fell
  const std::string setup = v.failure();
  EXPECT_NE(setup.find("CS_SETUP_TIME on spidev0.0, chip 0, frame 3, byte 0"), std::string::npos) << setup;
}

TEST(SanitizerPinFront, SixteenBitWordsLsbFirstAndAFastClockAreNamedOnceEach) {
  VirtualBoard v("chips=L6470 check=warn");
  PinFront f{v.board, BusSettings{10'000'000, 3, true, 16}};
  f.frame(0x1C);  // 0x38 bit-reversed: GetParam(CONFIG) on the wire
  EXPECT_EQ(f.frame(0x00), 0x74);  // 0x2E bit-reversed
  EXPECT_EQ(f.frame(0x00), 0x11);  // 0x88 bit-reversed
  std::string all;
  for (const std::string& l : v.log) all += l + "\n";
  EXPECT_EQ(v.log.size(), 3u) << all;
  EXPECT_NE(all.find("LSB_FIRST"), std::string::npos) << all;
  EXPECT_NE(all.find("WORD_SIZE: the host clocks 16-bit words"), std::string::npos) << all;
  EXPECT_NE(all.find("SCK_SPEED: SCK is 10 MHz"), std::string::npos) << all;
}

}  // namespace
}  // namespace l6470emu::test
