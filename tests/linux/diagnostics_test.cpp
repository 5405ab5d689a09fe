// The board's diagnostic log under a driver that repeats its mistake: each kind of diagnostic is
// shown a few times per chip, then counted, so a loop on a bad command cannot fill a disk.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "linux/device_board.hpp"
#include "run_program.hpp"

namespace l6470emu::test {
namespace {

TEST(BoardDiagnostics, ADriverLoopingOnABadCommandGetsTenLinesAndATallyAtEachPowerOfTen) {
  const std::string path = temp_socket_path("diag") + ".log";
  {
    ParseResult p = parse_board_config("bus=0 cs=0 chips=2xL6470 mode=3; time=virtual", "test");
    ASSERT_TRUE(p.config);
    DiagnosticLog log(path);
    DeviceBoard board(*p.config, log);
    const NewFile f = board.open(0, true);
    spi_ioc_transfer x{};
    x.tx_buf = 1;
    x.len = 2;
    const std::uint8_t tx[2] = {0xEB, 0x00};  // chip 0 gets 0xEB, a reserved opcode; chip 1 a NOP
    for (int i = 0; i < 20000; ++i) ASSERT_EQ(board.spi_message(f.handle, {&x, 1}, tx, {}), 2);
    close(f.fd);
  }
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  unlink(path.c_str());
  std::string all;
  for (const auto& l : lines) all += l + "\n";
  ASSERT_EQ(lines.size(), 13u) << all;
  EXPECT_EQ(lines[0], "l6470emu: spidev0.0: chip 0: WRONG_CMD: byte 0xEB: reserved opcode");
  EXPECT_EQ(lines[9], lines[0] + "  (further ones of this kind are counted, not shown)");
  EXPECT_EQ(lines[10], "l6470emu: spidev0.0: chip 0: WRONG_CMD: 100 so far");
  EXPECT_EQ(lines[12], "l6470emu: spidev0.0: chip 0: WRONG_CMD: 10000 so far");
}

TEST(BoardDiagnostics, NameTheChipAsTheBoardsNumberingCountsIt) {
  const std::string path = temp_socket_path("diag-mosi") + ".log";
  {
    ParseResult p = parse_board_config("bus=0 cs=0 chips=2xL6470 mode=3 numbering=mosi; time=virtual", "test");
    ASSERT_TRUE(p.config);
    DiagnosticLog log(path);
    DeviceBoard board(*p.config, log);
    const NewFile f = board.open(0, true);
    spi_ioc_transfer x{};
    x.tx_buf = 1;
    x.len = 2;
    const std::uint8_t tx[2] = {0xEB, 0x00};  // the chain's chip 0 (the MISO end) gets 0xEB
    ASSERT_EQ(board.spi_message(f.handle, {&x, 1}, tx, {}), 2);
    close(f.fd);
  }
  std::ifstream in(path);
  std::string first;
  std::getline(in, first);
  unlink(path.c_str());
  EXPECT_EQ(first, "l6470emu: spidev0.0: chip 1: WRONG_CMD: byte 0xEB: reserved opcode");
}

}  // namespace
}  // namespace l6470emu::test
