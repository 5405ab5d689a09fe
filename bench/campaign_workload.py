"""The Python driver of bench/campaign_bench.sh: the same work as campaign_workload.c through
python3-spidev (one xfer2 call per byte, as most drivers do): about 10 s of virtual time."""
import sys
import time

import spidev

s = spidev.SpiDev()
s.open(0, 0)
s.mode = 3


def cmd(op, arg=0, n=0):
    answer = 0
    s.xfer2([op])
    for i in range(n - 1, -1, -1):
        answer = answer << 8 | s.xfer2([(arg >> (8 * i)) & 0xFF])[0]
    return answer


def wait_for_motion():
    while True:
        st = cmd(0xD0, 0, 2)
        if not st & 0x1000 or not st & 0x0800:
            sys.exit(1)
        if st & 0x0002:
            return
        time.sleep(0.01)


cmd(0x05, 0x010, 2)
cmd(0x06, 0x010, 2)
cmd(0x07, 0x020, 2)
cmd(0xD0, 0, 2)
for _ in range(2):
    cmd(0x41, 20000, 3)
    wait_for_motion()
    cmd(0x60, 0, 3)
    wait_for_motion()
