#!/bin/sh
# A shell-script driver with Debian's spi-tools: spi-config reports the device's settings, and
# one spi-pipe sends GetStatus, Move(forward, 256 microsteps), then NOPs (each 8 µs of bus time
# at 1 MHz) while the move runs, then GetParam(ABS_POS). One byte per frame (-b 1): a chain of
# one chip. The device starts in mode 3 (mode=3 in the board description): spi-pipe has no mode
# option. Run it as: l6470emu run --chain "chips=L6470 mode=3" --scenario spi_tools.yaml -- sh spi_tools.sh
#
# Each process under `run` gets its own board: all the SPI traffic is in the one spi-pipe.
set -eu
spi-config -d /dev/spidev0.0 -q
{
  printf '\320\000\000'          # GetStatus: releases the power-up UVLO latch
  printf '\101\000\001\000'      # Move(forward, 0x000100 = 256 microsteps)
  head -c 20000 /dev/zero        # NOPs: 160 ms of bus time for the move to end
  printf '\041\000\000\000'      # GetParam(ABS_POS)
} | spi-pipe -d /dev/spidev0.0 -s 1000000 -b 1 | tail -c 3 | od -An -tx1
