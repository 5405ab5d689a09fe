"""Sends GetParam(MARK) messages in a loop until killed (one message = four transfers with
CS released between them, py-spidev's xfer). Prints one line once it runs."""
import sys

import spidev

s = spidev.SpiDev()
s.open(int(sys.argv[1]), int(sys.argv[2]))
s.mode = 3
print("running", flush=True)
while True:
    s.xfer([0x23, 0, 0, 0])
