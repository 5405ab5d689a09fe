"""The dSPIN commands the test scripts and the host-time benchmark send through Debian's
python3-spidev: one CS frame per byte, as one-chip drivers do. Only what they need."""
import threading

import spidev


def signed22(v):
    """ABS_POS and MARK as signed numbers (22-bit two's complement)."""
    return v - (1 << 22) if v & 0x200000 else v


class Dspin:
    """One chip on /dev/spidevBUS.CS in SPI mode 3; `lock` serialises commands of several threads."""

    def __init__(self, bus=0, cs=0, hz=5000000, lock=False):
        self.spi = spidev.SpiDev()
        self.spi.open(bus, cs)
        self.spi.mode = 3
        self.spi.max_speed_hz = hz
        self._lock = threading.Lock() if lock else None

    def cmd(self, *bs):
        if self._lock is None:
            return [self.spi.xfer2([b])[0] for b in bs]
        with self._lock:
            return [self.spi.xfer2([b])[0] for b in bs]

    def get_status(self):
        r = self.cmd(0xD0, 0, 0)
        return r[1] << 8 | r[2]

    def get_param(self, address, nbytes):
        v = 0
        for b in self.cmd(0x20 | address, *([0] * nbytes))[1:]:
            v = v << 8 | b
        return v

    def abs_pos(self):
        return signed22(self.get_param(0x01, 3))

    def move(self, forward, microsteps):
        self.cmd(0x40 | forward, (microsteps >> 16) & 0xFF, (microsteps >> 8) & 0xFF, microsteps & 0xFF)

    def run(self, forward, spd):
        self.cmd(0x50 | forward, (spd >> 16) & 0xFF, (spd >> 8) & 0xFF, spd & 0xFF)
