"""Retargeting a move: a motor going from 10 to 50 revolutions is told, as it passes 30, to go
back to 10. It decelerates, turns round, accelerates and ends exactly at 10 revolutions.

Units: revolutions of a 200-step motor at the L6470's power-up 1/128 microstepping
(1 rev = 25 600 microsteps of ABS_POS).

On the chip a GoTo is refused while BUSY is low (NOTPERF_CMD), so a host cannot just send the
new target mid-move. The chip's way: Run in reverse at the move's speed (accepted while moving:
the motor decelerates with DEC, turns round and accelerates with ACC), then, once the Run has
reached its speed and released BUSY, GoTo the target, which it reaches without overshoot.

    PYTHONPATH=build/python /usr/bin/python3 examples/retarget/retarget.py --plot retarget.png

Exit status 0 when the chip did all of that, 1 when not.
"""
import argparse
import sys

import l6470emu
from l6470emu import Reg

MICROSTEPS_PER_REV = 200 * 128
MAX_SPEED = 0x80   # 1953 full step/s = 9.8 rev/s (MAX_SPEED units: 15.26 step/s)
ACC = DEC = 0x8A   # 2008 full step/s² = 10 rev/s²


def rev(microsteps: int) -> float:
    return microsteps / MICROSTEPS_PER_REV


def at(revolutions: float) -> int:
    return round(revolutions * MICROSTEPS_PER_REV)


def wait_until(chain, condition, what: str, limit_s: float = 30.0, step_s: float = 0.001) -> None:
    """Advances virtual time in 1 ms steps until condition() holds."""
    waited = 0.0
    while not condition():
        chain.advance(seconds=step_s)
        waited += step_s
        if waited > limit_s:
            raise AssertionError(f"{what}: still not after {limit_s} s")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--plot", help="draw the run into this .png or .svg (needs python3-matplotlib)")
    args = parser.parse_args()

    # It shows the chip refusing a GoTo (NOTPERF_CMD) on purpose: the sanitizer lets that rule pass.
    chain = l6470emu.Chain("L6470", record=True, check_allow=["NOTPERF_CMD"])
    chain.get_status(0)  # clears the power-up UVLO flag
    chain.set_param(0, Reg.ACC, ACC)
    chain.set_param(0, Reg.DEC, DEC)
    chain.set_param(0, Reg.MAX_SPEED, MAX_SPEED)
    chain.set_param(0, Reg.ABS_POS, at(10))  # the motor stands at 10 rev

    chain.go_to(0, at(50))
    wait_until(chain, lambda: chain.position(0) >= at(30), "reaching 30 rev")
    told_at = chain.position(0)

    # A second GoTo while BUSY is low: the chip refuses it, as the datasheet says.
    chain.go_to(0, at(10))
    refused = chain.get_status(0)  # reads and clears NOTPERF_CMD
    assert refused.NOTPERF_CMD, f"a GoTo while BUSY should be refused, STATUS {refused}"

    # The chip's way: Run in reverse at the move's speed (SPEED units: MAX_SPEED << 10) ...
    chain.run(0, forward=False, speed=MAX_SPEED << 10)
    peak = told_at
    def turned_and_at_speed():
        nonlocal peak
        peak = max(peak, chain.position(0))
        return chain.busy_pin(0)  # BUSY released: the Run is at its speed, in reverse
    wait_until(chain, turned_and_at_speed, "the reverse Run reaching its speed")
    turned_round = chain.now_seconds
    # ... then GoTo the new target.
    chain.go_to(0, at(10))
    assert not chain.status(0).NOTPERF_CMD, "the GoTo after the Run was refused"
    wait_until(chain, lambda: chain.busy_pin(0), "the GoTo ending")
    end = chain.position(0)

    motion = l6470emu.motion(chain.trace).chips[0]
    speeds = motion.speed
    went_forward = max(speeds) > 0
    went_back = min(speeds) < 0
    print(f"told at {rev(told_at):.3f} rev to go back to 10; it decelerated to {rev(peak):.3f} rev, turned round,")
    print(f"ran back at speed from t={turned_round:.3f} s and stopped at {rev(end):.3f} rev "
          f"(ABS_POS {end}) at t={chain.now_seconds:.3f} s")

    ok = True
    for good, what in ((end == at(10), f"ends exactly at 10 rev (ABS_POS {end}, expected {at(10)})"),
                       (peak > told_at, "overshoots 30 rev while decelerating"),
                       (went_forward and went_back, "turns round (speed changes sign)"),
                       (chain.peek(0, Reg.SPEED) == 0 and chain.busy_pin(0), "stands still with BUSY released")):
        print(f"  {'ok  ' if good else 'FAIL'} {what}")
        ok = ok and good

    if args.plot:
        from l6470emu import plot as pictures
        if pictures.available():
            out = pictures.plot(chain, args.plot, position_unit=("rev", MICROSTEPS_PER_REV),
                                title="retarget: 10 → 50 rev, told at 30 to go back to 10")
            print(f"plot: {out}")
        else:
            print(f"plot skipped: {pictures.MATPLOTLIB_MISSING}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
