"""The Python client of the preload benchmark (bench/preload_bench.sh): Debian's python3-spidev
polling GetStatus of one L6470 in a tight loop, one CS frame per byte as one-chip drivers send it
(xfer2([0xD0]), then two xfer2([0]) that carry STATUS back: three round trips per poll).
Usage: /usr/bin/python3 bench/preload_poll.py /dev/spidevB.C ROUND_TRIPS
Prints "COUNT WALL_SECONDS PER_WALL_SECOND HOST_SECONDS CPU_SECONDS" as
l6470emu_preload_roundtrips does: wall time from the raw system call (under time=virtual every
clock the program reads through the C library is the board's), host time from time.monotonic(),
the process's CPU time (never virtual)."""
import ctypes
import re
import sys
import time

import spidev

libc = ctypes.CDLL(None, use_errno=True)
SYS_clock_gettime = 228  # x86-64


class Timespec(ctypes.Structure):
    _fields_ = [("tv_sec", ctypes.c_long), ("tv_nsec", ctypes.c_long)]


def wall_seconds():
    t = Timespec()
    libc.syscall(SYS_clock_gettime, time.CLOCK_MONOTONIC, ctypes.byref(t))
    return t.tv_sec + t.tv_nsec / 1e9


def main():
    m = re.fullmatch(r"/dev/spidev(\d+)\.(\d+)", sys.argv[1])
    n = int(sys.argv[2]) // 3
    spi = spidev.SpiDev()
    spi.open(int(m[1]), int(m[2]))
    spi.mode = 3
    spi.max_speed_hz = 5000000
    xfer2 = spi.xfer2
    wall0, host0, cpu0 = wall_seconds(), time.monotonic(), time.process_time()
    for _ in range(n):
        xfer2([0xD0])
        xfer2([0])
        xfer2([0])
    wall, host, cpu = wall_seconds() - wall0, time.monotonic() - host0, time.process_time() - cpu0
    print(f"{3 * n} {wall:.6f} {3 * n / wall:.0f} {host:.6f} {cpu:.6f}")


if __name__ == "__main__":
    main()
