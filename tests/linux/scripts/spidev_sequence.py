"""GetStatus, SetParam, GetParam and a Move through Debian's python3-spidev, one CS frame per
byte (xfer2 of one byte), as most L6470 drivers do. Prints key=value lines for the test."""
import sys
import time

import spidev

bus, cs = int(sys.argv[1]), int(sys.argv[2])
s = spidev.SpiDev()
s.open(bus, cs)
s.mode = 3
s.max_speed_hz = 4000000
print(f"settings=mode{s.mode} bits{s.bits_per_word} {s.max_speed_hz}Hz")


frames = 0


def frame(b):
    global frames
    frames += 1
    return s.xfer2([b])[0]


def command(*bs):
    return [frame(b) for b in bs]


def get_param(address, nbytes):
    r = command(0x20 | address, *([0] * nbytes))
    v = 0
    for b in r[1:]:
        v = v << 8 | b
    return v


def get_status():
    r = command(0xD0, 0, 0)
    return r[1] << 8 | r[2]


print(f"status0=0x{get_status():04X}")
print(f"status1=0x{get_status():04X}")
command(0x07, 0x00, 0x30)  # SetParam(MAX_SPEED, 0x030)
print(f"max_speed=0x{get_param(0x07, 2):03X}")
command(0x05, 0x00, 0xFF)  # SetParam(ACC, 0x0FF)
print(f"acc=0x{get_param(0x05, 2):03X}")
steps = 6400
command(0x41, (steps >> 16) & 0x3F, (steps >> 8) & 0xFF, steps & 0xFF)  # Move FWD
st = get_status()
print(f"busy_after_move={0 if st & 0x0002 else 1}")
deadline = time.monotonic() + 10
while time.monotonic() < deadline and not get_status() & 0x0002:
    time.sleep(0.01)
print(f"abs_pos={get_param(0x01, 3)}")
print(f"status_end=0x{get_status():04X}")
print(f"frames={frames}")
s.close()
