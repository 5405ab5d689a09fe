"""A host program under time=virtual, through Debian's python3-spidev and python3-libgpiod: its
own clock, sleeps, locks and threads run on the board's virtual time. One scenario per run,
chosen by the first argument; prints key=value lines for the test.

  run-sleep SPD        Run forward at SPD (2^-28 step/tick), sleep 1 s, read ABS_POS and SPEED
  sleep-around-moves   12 Moves, each followed by a 5 s sleep: 60 s of the program's time
  threads              thread A waits on BUSY edge events while thread B moves, sleeps and polls STATUS
  idle                 a thread blocked in a raw read system call while the main thread sleeps 5 s
  fork                 a forked child sleeps 10 s on its own copy of the clock; the parent waits for it
  subprocess           a Python child started with subprocess between two GetStatus of the parent
"""
import ctypes
import os
import sys
import threading
import time


def real_seconds():
    """The machine's uptime: real time, which the library does not virtualise (10 ms steps)."""
    with open("/proc/uptime") as f:
        return float(f.read().split()[0])


scenario = sys.argv[1]
t_start = time.monotonic_ns()  # the board's tick 0: nothing waited before this line

if scenario == "idle":
    r, w = os.pipe()
    got = []
    buf = ctypes.create_string_buffer(1)
    # A raw read system call (0 on x86-64, 63 on arm64): blocked outside any covered wait.
    sys_read = 63 if os.uname().machine == "aarch64" else 0
    reader = threading.Thread(target=lambda: got.append(buf.raw if ctypes.CDLL(None).syscall(sys_read, r, buf, 1) == 1 else b""))
    reader.start()
    t0 = time.monotonic_ns()
    time.sleep(5)
    print(f"slept_ns={time.monotonic_ns() - t0}")
    os.write(w, b"x")
    reader.join()
    print(f"reader_got={got[0].decode()}")
    sys.exit(0)

if scenario == "fork":
    t0 = time.monotonic_ns()
    pid = os.fork()
    if pid == 0:
        time.sleep(10)
        print(f"child_slept_ns={time.monotonic_ns() - t0}", flush=True)
        os._exit(0)
    os.waitpid(pid, 0)  # a real wait: the parent's time does not move meanwhile
    time.sleep(0.5)
    print(f"parent_elapsed_ns={time.monotonic_ns() - t0}")
    sys.exit(0)

from dspin_spidev import Dspin, signed22  # noqa: E402

chip = Dspin(hz=4000000, lock=True)
s = chip.spi
cmd, get_status, get_param, move = chip.cmd, chip.get_status, chip.get_param, chip.move


if scenario == "subprocess":  # the device is opened after a sleep, the trace starts then
    time.sleep(0.5)
    print(f"status_before=0x{get_status():04X}")
    import subprocess

    child = subprocess.run(
        [sys.executable, "-c", "import time; t = time.monotonic_ns(); time.sleep(5); print(time.monotonic_ns() - t)"],
        capture_output=True, text=True)
    print(f"child_slept_ns={child.stdout.strip()}")
    time.sleep(1)
    print(f"status_after=0x{get_status():04X} elapsed_ns={time.monotonic_ns() - t_start}")
    sys.exit(0)

get_status()  # clear the power-up UVLO

if scenario == "run-sleep":
    spd = int(sys.argv[2])
    cmd(0x51, (spd >> 16) & 0xFF, (spd >> 8) & 0xFF, spd & 0xFF)  # Run forward
    t_run = time.monotonic_ns()  # the Run's CS rise + the CS-high time
    real0 = real_seconds()
    time.sleep(1)
    real1 = real_seconds()
    t_slept = time.monotonic_ns()
    s.xfer2([0x21])  # GetParam(ABS_POS): the value is latched at this frame's CS rise
    t_latch = time.monotonic_ns()
    pos = 0
    for b in cmd(0, 0, 0):
        pos = pos << 8 | b
    print(f"slept_ns={t_slept - t_run} latch_ns={t_latch - t_run} real_sleep_s={real1 - real0:.2f}")
    print(f"abs_pos={signed22(pos)} speed={get_param(0x04, 3)}")

elif scenario == "sleep-around-moves":
    real0 = real_seconds()
    t0 = time.monotonic_ns()
    positions = []
    for k in range(12):
        move(1, 1600)
        time.sleep(5)
        positions.append(signed22(get_param(0x01, 3)))
    print(f"elapsed_ns={time.monotonic_ns() - t0} real_s={real_seconds() - real0:.2f}")
    print("positions=" + ",".join(str(p) for p in positions))

elif scenario == "threads":
    import gpiod

    chip = gpiod.Chip("gpiochip0")
    busy = chip.find_line("BUSY")
    busy.request(consumer="watcher", type=gpiod.LINE_REQ_EV_BOTH_EDGES)
    events = []
    polls = []
    done = threading.Event()

    def watcher():  # thread A
        while not done.is_set():
            if not busy.event_wait(sec=0, nsec=300_000_000):
                continue
            ev = busy.event_read()
            seen = time.monotonic_ns()
            stamp = ev.sec * 1_000_000_000 + ev.nsec
            kind = "rising" if ev.type == gpiod.LineEvent.RISING_EDGE else "falling"
            events.append(f"{kind}@{stamp - t_start}/seen@{seen - t_start}")

    def poller():  # thread B
        for k in range(3):
            move(k % 2, 800 * (k + 1))
            while True:
                time.sleep(0.01)
                if get_status() & 0x0002:  # BUSY bit set: not busy
                    break
                polls.append(k)
            polls.append(f"done{k}@{time.monotonic_ns() - t_start}")
            time.sleep(0.05)
        done.set()

    a = threading.Thread(target=watcher)
    b = threading.Thread(target=poller)
    a.start()
    b.start()
    b.join()
    a.join()
    print("events=" + ",".join(events))
    print("polls=" + ",".join(str(p) for p in polls))
    print(f"end_ns={time.monotonic_ns() - t_start} abs_pos={signed22(get_param(0x01, 3))}")
