"""Time as a host program sees it, through Debian's python3-spidev (and python3-libgpiod):
what a driver that polls, sleeps or waits on BUSY measures on its own clock. One scenario per
run, chosen by the first argument; prints key=value lines for the test.

  poll-move FULL_STEPS SCK_HZ   Move, then poll GetStatus without pause until BUSY is released
  run-poll SCK_HZ               Run at 200 step/s, poll GetStatus for 1 s, read ABS_POS
  run-sleep                     Run at 200 step/s, sleep 1 s, read SPEED (a ported vendor example)
  edge-after-poll               a polled Move, then a Move whose BUSY edges arrive as gpio events
"""
import sys
import time

import spidev

s = spidev.SpiDev()
s.open(0, 0)
s.mode = 3
s.max_speed_hz = 5000000


def cmd(*bs):
    return [s.xfer2([b])[0] for b in bs]


def get_status():
    r = cmd(0xD0, 0, 0)
    return r[1] << 8 | r[2]


def get_param(address, nbytes):
    v = 0
    for b in cmd(0x20 | address, *([0] * nbytes))[1:]:
        v = v << 8 | b
    return v


def abs_pos():
    v = get_param(0x01, 3)
    return v - (1 << 22) if v & 0x200000 else v


def move(forward, microsteps):
    cmd(0x40 | forward, (microsteps >> 16) & 0xFF, (microsteps >> 8) & 0xFF, microsteps & 0xFF)


def run(forward, spd):
    cmd(0x50 | forward, (spd >> 16) & 0xFF, (spd >> 8) & 0xFF, spd & 0xFF)


SPD_200 = round(200 * 250e-9 * 2**28)  # 200 full steps/s in 2^-28 step/tick
scenario = sys.argv[1]
cmd(0xC0)  # ResetDevice: a daemon keeps the board between programs; start from power-up
get_status()  # clear the power-up UVLO

if scenario == "poll-move":
    s.max_speed_hz = int(sys.argv[3])
    t0 = time.monotonic()
    move(1, int(sys.argv[2]) * 128)
    t_sent = time.monotonic()
    polls = 0
    while not get_status() & 0x0002:
        polls += 1
    t_end = time.monotonic()
    print(f"start={t0:.9f} sent={t_sent:.9f} released={t_end:.9f} polls={polls}")
elif scenario == "run-poll":
    s.max_speed_hz = int(sys.argv[2])
    run(1, SPD_200)
    t0 = time.monotonic()
    while time.monotonic() - t0 < 1.0:
        get_status()
    pos = abs_pos()
    print(f"elapsed={time.monotonic() - t0:.9f} abs_pos={pos}")
elif scenario == "run-sleep":
    run(1, SPD_200)
    time.sleep(1)
    print(f"speed=0x{get_param(0x04, 3):05X} abs_pos={abs_pos()}")
elif scenario == "edge-after-poll":
    import gpiod
    busy = gpiod.Chip("gpiochip0").find_line("BUSY")
    busy.request(consumer="host-time", type=gpiod.LINE_REQ_EV_BOTH_EDGES)
    move(1, 200 * 128)  # first a Move polled hard, as in poll-move
    while not get_status() & 0x0002:
        pass
    while busy.event_wait(sec=0):
        busy.event_read()  # the first Move's edges
    t0 = time.monotonic_ns()
    move(0, 200 * 128)
    t_sent = time.monotonic_ns()
    rising = None
    while rising is None and busy.event_wait(sec=5):
        ev = busy.event_read()
        if ev.type == gpiod.LineEvent.RISING_EDGE:
            rising = ev.sec * 1000000000 + ev.nsec
    t_recv = time.monotonic_ns()
    print(f"start={t0} sent={t_sent} edge={rising} received={t_recv}")
else:
    sys.exit(f"unknown scenario {scenario}")
