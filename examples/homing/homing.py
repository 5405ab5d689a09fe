"""Homing against a limit switch: GoUntil in reverse until the switch closes, ReleaseSW
forward until it opens again, ResetPos there, then an absolute GoTo.

The carriage and its switch are simulated here: the carriage follows the motor's microsteps,
and the example closes the chip's SW input (the backdoor, Chain.set_sw_pin) while the carriage
is at or below the switch, as the mechanics would. CONFIG.SW_MODE = 1 (user disposal), so the
switch stops GoUntil with a SoftStop instead of a hard stop.

Units: microsteps of ABS_POS (the power-up 1/128 step mode); the carriage starts 51 200
microsteps (2 revolutions) above the switch.

    PYTHONPATH=build/python /usr/bin/python3 examples/homing/homing.py --plot homing.png

Exit status 0 when homing ends where it should, 1 when not.
"""
import argparse
import sys

import l6470emu
from l6470emu import Reg

SWITCH_AT = 0             # the switch is closed while the carriage is at or below this (microsteps)
START = 51_200            # where the carriage starts
TARGET = 10_000           # the GoTo after homing, microsteps from the switch edge
GO_UNTIL_STEPS_PER_S = 200
SW_MODE = 1 << 4          # CONFIG.SW_MODE: 1 = user disposal


def speed_register(steps_per_s: float) -> int:
    """A speed in full steps/s in SPEED units (2^-28 step per 250 ns tick)."""
    return round(steps_per_s * 2**28 / l6470emu.TICKS_PER_SECOND)


class Carriage:
    """Follows chip 0's ABS_POS changes and drives its SW pin from the physical position."""

    def __init__(self, chain, position: int):
        self.chain = chain
        self.position = position
        self.last = chain.position(0)

    def closed(self) -> bool:
        return self.position <= SWITCH_AT

    def follow(self) -> None:
        now = self.chain.position(0)
        delta = (now - self.last) & 0x3FFFFF          # ABS_POS is 22 bits
        self.position += delta - (1 << 22) if delta & 0x200000 else delta
        self.last = now
        if self.closed() == self.chain.sw_pin(0):    # SW low = closed
            self.chain.set_sw_pin(0, not self.closed())
            self.last = self.chain.position(0)        # the switch event may reset ABS_POS: no movement
        
    def resync(self) -> None:
        """After a command that sets ABS_POS without moving the motor (ResetPos)."""
        self.last = self.chain.position(0)

    def run_until_idle(self, limit_s: float = 60.0, step_s: float = 0.0001) -> None:
        waited = 0.0
        self.follow()
        while not self.chain.busy_pin(0):
            self.chain.advance(seconds=step_s)
            self.follow()
            waited += step_s
            if waited > limit_s:
                raise AssertionError(f"the motor is still busy after {limit_s} s")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--plot", help="draw the run into this .png or .svg (needs python3-matplotlib)")
    args = parser.parse_args()

    chain = l6470emu.Chain("L6470", record=True)
    chain.get_status(0)
    chain.set_param(0, Reg.CONFIG, chain.get_param(0, Reg.CONFIG) | SW_MODE)
    carriage = Carriage(chain, START)
    checks = []

    chain.go_until(0, copy_to_mark=False, forward=False, speed=speed_register(GO_UNTIL_STEPS_PER_S))
    carriage.run_until_idle()
    status = chain.get_status(0)
    print(f"GoUntil:   stopped at carriage {carriage.position}, ABS_POS {chain.position(0)}, switch "
          f"{'closed' if carriage.closed() else 'open'}, SW_EVN {status.SW_EVN}")
    checks.append((carriage.closed() and status.SW_EVN, "GoUntil stops on the closed switch (SW_EVN)"))

    chain.release_sw(0, copy_to_mark=False, forward=True)
    carriage.run_until_idle()
    print(f"ReleaseSW: stopped at carriage {carriage.position}, switch {'closed' if carriage.closed() else 'open'}")
    checks.append((not carriage.closed() and carriage.position - SWITCH_AT <= 4,
                   "ReleaseSW stops just off the switch (within 4 microsteps)"))

    chain.reset_pos(0)
    carriage.resync()
    home = carriage.position
    checks.append((chain.position(0) == 0, "ResetPos makes this ABS_POS 0"))

    chain.go_to(0, TARGET)
    carriage.run_until_idle()
    print(f"GoTo({TARGET}): ABS_POS {chain.position(0)}, carriage {carriage.position} "
          f"= home {home} + {carriage.position - home}")
    checks.append((chain.position(0) == TARGET and carriage.position - home == TARGET,
                   f"GoTo ends {TARGET} microsteps from home, on ABS_POS and on the carriage"))

    ok = True
    for good, what in checks:
        print(f"  {'ok  ' if good else 'FAIL'} {what}")
        ok = ok and bool(good)

    if args.plot:
        from l6470emu import plot as pictures
        if pictures.available():
            out = pictures.plot(chain, args.plot, title="homing: GoUntil, ReleaseSW, ResetPos, GoTo(10000)")
            print(f"plot: {out}")
        else:
            print(f"plot skipped: {pictures.MATPLOTLIB_MISSING}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
