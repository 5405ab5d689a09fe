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

from dspin_spidev import Dspin

chip = Dspin(hz=5000000)
s = chip.spi
cmd, get_status, get_param, abs_pos, move, run = chip.cmd, chip.get_status, chip.get_param, chip.abs_pos, chip.move, chip.run

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
