"""Homing through python3-spidev against the board's mechanical axis: GoUntil in reverse onto the
home switch (the axis closes SW, not this program), ReleaseSW forward off it, ResetPos, GoTo.
Waits by polling GetStatus with time.sleep between polls (virtual time: the sleeps take none).
Prints key=value lines; exit 1 when the motor does not home.

    homing.py BUS CS [MOVE_MICROSTEPS]   (an optional Move forward after the GoTo)
"""
import sys
import time

import spidev

bus, cs = int(sys.argv[1]), int(sys.argv[2])
extra = int(sys.argv[3]) if len(sys.argv) > 3 else 0
s = spidev.SpiDev()
s.open(bus, cs)
s.mode = 3
s.max_speed_hz = 4000000


def command(*bs):
    return [s.xfer2([b])[0] for b in bs]


def get_status():
    r = command(0xD0, 0, 0)
    return r[1] << 8 | r[2]


def abs_pos():
    r = command(0x21, 0, 0, 0)
    v = r[1] << 16 | r[2] << 8 | r[3]
    return v - (1 << 22) if v & 0x200000 else v


def wait_idle(limit_s=30.0):
    waited = 0.0
    while not get_status() & 0x0002:  # BUSY low = busy
        time.sleep(0.01)
        waited += 0.01
        if waited > limit_s:
            print("FAIL still busy")
            sys.exit(1)


get_status()
command(0x82, 0x00, 0x34, 0x6E)  # GoUntil reverse at 200 step/s, ACT=0
wait_idle()
status = get_status()
print(f"until_status=0x{status:04X}")  # SW_F (bit 2) set: the switch is closed
command(0x93)                      # ReleaseSW forward
wait_idle()
print(f"released_status=0x{get_status():04X}")
command(0xD8)                      # ResetPos
command(0x60, 0x00, 0x27, 0x10)    # GoTo(10000)
wait_idle()
pos = abs_pos()
print(f"abs_pos={pos}")
if extra:
    command(0x41, extra >> 16 & 0xFF, extra >> 8 & 0xFF, extra & 0xFF)  # Move forward
    wait_idle()
    print(f"moved_to={abs_pos()}")
ok = status & 0x0004 and pos == 10000
print("homed" if ok else "FAIL not homed")
sys.exit(0 if ok else 1)
