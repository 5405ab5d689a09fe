"""python3-libgpiod (1.6, v1 uAPI) watching BUSY while python3-spidev runs a Move: BUSY falls
when the Move is decoded and rises when it ends. Prints key=value lines for the test."""
import sys
import time

import gpiod
import spidev

s = spidev.SpiDev()
s.open(int(sys.argv[1]), int(sys.argv[2]))
s.mode = 3
s.max_speed_hz = 4000000
chip = gpiod.Chip(sys.argv[3] if len(sys.argv) > 3 else "gpiochip0")
print(f"chip={chip.name()} label={chip.label()} lines={chip.num_lines()}")
busy = chip.find_line("BUSY")
flag = chip.find_line("FLAG")
busy.request(consumer="busy-test", type=gpiod.LINE_REQ_EV_BOTH_EDGES)
flag.request(consumer="flag-test", type=gpiod.LINE_REQ_DIR_IN)
print(f"busy_before={busy.get_value()} flag_before={flag.get_value()}")
for b in (0xD0, 0, 0):  # GetStatus clears the power-up UVLO: FLAG rises
    s.xfer2([b])
print(f"flag_after_getstatus={flag.get_value()}")
t0 = time.monotonic()
for b in (0x40, 0x00, 0x64, 0x00):  # Move REV 25600 microsteps: about 0.63 s, room for a loaded host
    s.xfer2([b])
print(f"busy_during={busy.get_value()}")
edges = []
while busy.event_wait(sec=5):
    ev = busy.event_read()
    edges.append("rising" if ev.type == gpiod.LineEvent.RISING_EDGE else "falling")
    if edges[-1] == "rising":
        break
print(f"edges={','.join(edges)}")
print(f"move_seconds={time.monotonic() - t0:.3f}")
print(f"busy_after={busy.get_value()}")
r = [s.xfer2([b])[0] for b in (0x21, 0, 0, 0)]
pos = r[1] << 16 | r[2] << 8 | r[3]
if pos & 0x200000:
    pos -= 1 << 22
print(f"abs_pos={pos}")
