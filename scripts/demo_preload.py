"""The README demo: an unmodified Python program that drives a daisy chain of L6470s through
the real spidev and libgpiod APIs (Debian's python3-spidev and python3-libgpiod). Nothing here
knows about the emulator: scripts/quickstart.sh demo runs it under libl6470emu-preload.so,
which provides /dev/spidev0.0 and /dev/gpiochip0. On a board with real chips it runs unchanged.

Chain numbering: chip 0 drives MISO, so in a frame of N bytes byte k is chip k's."""
import sys
import time

import gpiod
import spidev

CHIPS = int(sys.argv[1]) if len(sys.argv) > 1 else 3

spi = spidev.SpiDev()
spi.open(0, 0)
spi.mode = 3
spi.max_speed_hz = 4_000_000


def chain_command(per_chip):
    """Sends per_chip[k] (same length for all) to chip k: one CS frame per byte position."""
    frames = list(zip(*per_chip))
    answers = [spi.xfer2(list(f)) for f in frames]
    return [[answers[i][k] for i in range(len(frames))] for k in range(CHIPS)]


def get_status_all():
    return [a[1] << 8 | a[2] for a in chain_command([[0xD0, 0, 0]] * CHIPS)]


def abs_pos_all():
    out = []
    for a in chain_command([[0x21, 0, 0, 0]] * CHIPS):
        v = a[1] << 16 | a[2] << 8 | a[3]
        out.append(v - (1 << 22) if v & 0x200000 else v)
    return out


chip = gpiod.Chip("gpiochip0")
print(f"{chip.name()} [{chip.label()}]: {chip.num_lines()} lines; spidev0.0 in SPI mode {spi.mode} at {spi.max_speed_hz} Hz")
busy = [chip.find_line(f"BUSY{k}" if CHIPS > 1 else "BUSY") for k in range(CHIPS)]
flag = [chip.find_line(f"FLAG{k}" if CHIPS > 1 else "FLAG") for k in range(CHIPS)]
bulk = gpiod.LineBulk(busy)
bulk.request(consumer="demo", type=gpiod.LINE_REQ_EV_BOTH_EDGES)
flags = gpiod.LineBulk(flag)
flags.request(consumer="demo", type=gpiod.LINE_REQ_DIR_IN)

pins = flags.get_values()  # read before GetStatus, which clears the power-up UVLO flag
print(f"power-up: FLAG pins {pins} (0 = alarm), STATUS {' '.join(f'0x{s:04X}' for s in get_status_all())}")
print(f"after GetStatus: FLAG pins {flags.get_values()}, STATUS {' '.join(f'0x{s:04X}' for s in get_status_all())}")

# Chip k moves (k+1) x 6400 microsteps, even chips forward, odd ones in reverse.
moves = []
for k in range(CHIPS):
    n = (k + 1) * 6400
    moves.append([0x40 | (k % 2 == 0), (n >> 16) & 0x3F, (n >> 8) & 0xFF, n & 0xFF])
t0 = time.monotonic()
chain_command(moves)
print(f"Move sent; BUSY pins: {bulk.get_values()} (0 = busy)")

running = set(range(CHIPS))
while running:
    for line in bulk.event_wait(sec=10) or []:
        ev = line.event_read()
        k = busy.index(line) if line in busy else [b.offset() for b in busy].index(line.offset())
        edge = "released" if ev.type == gpiod.LineEvent.RISING_EDGE else "pulled low"
        print(f"t={time.monotonic() - t0:5.2f} s  chip {k}: BUSY {edge}  ABS_POS {abs_pos_all()}")
        if ev.type == gpiod.LineEvent.RISING_EDGE:
            running.discard(k)

print(f"final ABS_POS: {abs_pos_all()}")
print(f"final STATUS:  {' '.join(f'0x{s:04X}' for s in get_status_all())}")
