"""SetParam(MARK, VALUE) through python3-spidev."""
import sys

import spidev

s = spidev.SpiDev()
s.open(int(sys.argv[1]), int(sys.argv[2]))
s.mode = 3
v = int(sys.argv[3], 0)
for b in (0x03, (v >> 16) & 0x3F, (v >> 8) & 0xFF, v & 0xFF):
    s.xfer2([b])
print("ok")
