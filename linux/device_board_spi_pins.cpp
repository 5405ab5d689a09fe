// DeviceBoard: a chain's SPI at its pins as four gpio lines (CS, SCK, MOSI, MISO) for a program
// that bit-bangs the bus through the gpio character device (an spi-gpio-style driver). The
// edges go to the Board's pin-level bus (Board::drive_chip_select, drive_spi_clock,
// drive_spi_data, spi_data_out), which turns them into whole bytes at the board's time.
#include <linux/gpio.h>

#include "linux/device_board_internal.hpp"

namespace l6470emu {

void DeviceBoard::set_spi_line(GpioDev& g, SpiLine line, bool level, bool at_request) {
  LineDev& l = g.lines[g.layout.offset(line)];
  const std::size_t chain = g.chain;
  switch (line) {
    case SpiLine::cs: {
      l.out_value = level;
      const bool selected = !level;  // CS is active low
      if (selected == board_.chip_selected(chain)) return;
      if (selected) {
        g.cs_low_from_request = at_request;  // a line requested as an output low: not a frame the program meant
      } else if (!board_.spi_pins(chain).frame_clocked() && board_.chain(chain).bytes_in_frame() == 0 &&
                 !g.cs_low_from_request) {
        const std::string what = "a chip-select frame with no clock edge: nothing reached the chips";
        if (!g.clockless_said) log_.line(g.name + ": " + board_.chain_name(chain) + ": " + what + " (said once)");
        g.clockless_said = true;
        board_.report_spi_pins(chain, what);
      }
      board_.drive_chip_select(chain, selected);
      return;
    }
    case SpiLine::sck: {
      l.out_value = level;
      const bool rising_unselected = level && !board_.spi_pins(chain).ck() && !board_.chip_selected(chain);
      board_.drive_spi_clock(chain, level);
      if (rising_unselected && ++g.unselected_rising == 8) {
        // A byte's worth of clocks with CS high: the program's CS is not this chain's CS line.
        const std::string what = "clock edges on SCK while CS is high: nothing shifts";
        log_.line(g.name + ": " + board_.chain_name(chain) + ": " + what + " (is CS the line the program drives low?)");
        board_.report_spi_pins(chain, what);
      }
      return;
    }
    case SpiLine::mosi:
      l.out_value = level;
      board_.drive_spi_data(chain, level);
      return;
    case SpiLine::miso:
      // The host drives the chips' output: it reads back its own value; the chips do not hear it.
      if (l.out_value != level && !g.miso_driven_said)
        log_.line(g.name + ": the host drives MISO, an output of the chips (ignored by them; said once)");
      g.miso_driven_said = g.miso_driven_said || l.out_value != level;
      l.out_value = level;
      return;
  }
}

bool DeviceBoard::spi_line_level(GpioDev& g, unsigned offset) {
  const LineDev& l = g.lines[offset];
  const SpiLine line = *g.layout.spi_line(offset);
  if (line != SpiLine::miso || (l.flags & GPIO_V2_LINE_FLAG_OUTPUT)) return l.out_value;  // the host's own level
  // Chip 0's SDO while CS is low; floating otherwise: a pull-up bias reads high, else low.
  if (const auto sdo = board_.spi_data_out(g.chain)) return *sdo;
  return (l.flags & GPIO_V2_LINE_FLAG_BIAS_PULL_UP) != 0;
}

}  // namespace l6470emu
