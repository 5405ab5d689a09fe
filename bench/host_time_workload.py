"""A driver-test workload for the host-time benchmark: 60 s of host time spent sleeping,
polling and waiting on BUSY around moves, through Debian's python3-spidev and python3-libgpiod
(one L6470 at its power-up profile). Prints one line per move (how it waited, the host-measured
duration) and the final state; run under the preload in wall or virtual time."""
import os
import sys
import time

import gpiod

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "linux", "scripts"))
from dspin_spidev import Dspin  # noqa: E402

chip = Dspin(hz=5000000)
busy = gpiod.Chip("gpiochip0").find_line("BUSY")
busy.request(consumer="bench", type=gpiod.LINE_REQ_EV_BOTH_EDGES)
cmd, get_status, get_param = chip.cmd, chip.get_status, chip.get_param


def wait_released(how):
    """Returns the host time at which BUSY was seen released."""
    if how == "poll":
        while not get_status() & 0x0002:
            pass
    elif how == "poll-sleep-1ms":
        while not get_status() & 0x0002:
            time.sleep(0.001)
    else:  # gpio: the BUSY rising edge as a libgpiod event, stamped by the board
        while True:
            if not busy.event_wait(sec=10):
                raise SystemExit("no BUSY edge within 10 s")
            ev = busy.event_read()
            if ev.type == gpiod.LineEvent.RISING_EDGE:
                return ev.sec + ev.nsec / 1e9
    return time.monotonic()


start = time.monotonic()
get_status()  # clear the power-up UVLO
plan = [(1, 200, "poll"), (0, 200, "poll-sleep-1ms"), (1, 200, "gpio"),
        (1, 1000, "poll"), (0, 1000, "poll-sleep-1ms"), (0, 1000, "gpio")]
for i, (forward, full_steps, how) in enumerate(plan):
    n = full_steps * 128
    while busy.event_wait(sec=0):
        busy.event_read()
    t0 = time.monotonic()
    cmd(0x40 | forward, (n >> 16) & 0xFF, (n >> 8) & 0xFF, n & 0xFF)
    released = wait_released(how)
    pos = get_param(0x01, 3)
    print(f"move {i} dir={forward} full_steps={full_steps} wait={how} seconds={released - t0:.6f} "
          f"abs_pos={pos - (1 << 22) if pos & 0x200000 else pos}")
    time.sleep(6.0)  # the host does something else between moves
spd = round(200 * 250e-9 * 2**28)
cmd(0x51, (spd >> 16) & 0xFF, (spd >> 8) & 0xFF, spd & 0xFF)  # Run forward at 200 step/s
time.sleep(5.0)
speed = get_param(0x04, 3)
cmd(0xB0)  # SoftStop
while not get_status() & 0x0002:
    time.sleep(0.01)
cmd(0x70)  # GoHome: where the Run stopped depends on the host's sleep to the microsecond; home does not
while not get_status() & 0x0002:
    time.sleep(0.01)
# Spend the rest of 60 s of host time idling in small sleeps, as a polling loop would.
while time.monotonic() - start < 60.0:
    time.sleep(0.05)
    get_status()
pos = get_param(0x01, 3)
print(f"final abs_pos={pos - (1 << 22) if pos & 0x200000 else pos} speed_after_run=0x{speed:05X} "
      f"status=0x{get_status():04X} host_seconds={time.monotonic() - start:.3f}")
