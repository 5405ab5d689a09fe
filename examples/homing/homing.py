"""Homing with the axis model: a motor, its carriage, a hard stop and a home switch behind the
chip (Chain.attach_axis), so the switch and the stall come from the mechanics, not from the
test. Two ways to find home:

1. Switch homing: GoUntil in reverse until the home switch closes (SW_MODE = 1: a SoftStop),
   ReleaseSW forward until it opens, ResetPos there, then an absolute GoTo.
2. Stall-based (sensorless) homing: Run slowly in reverse into the hard stop with STALL_TH set
   between the running current and the blocked current; the STEP_LOSS flags say the rotor
   stopped following; HardStop, ResetPos, GoTo.

The axis's true position (Chain.axis) is checked against ABS_POS after each homing. Units:
microsteps of ABS_POS (1/128 step, the power-up step mode).

    PYTHONPATH=build/python /usr/bin/python3 examples/homing/homing.py --plot homing.png

Exit status 0 when both homings end where they should, 1 when not.
"""
import argparse
import sys

import l6470emu
from l6470emu import Reg

START = 51_200      # where the carriage starts (2 revolutions above home)
TARGET = 10_000     # the GoTo after homing, microsteps from home
SW_MODE = 1 << 4    # CONFIG.SW_MODE: 1 = user disposal
STALL_TH = 0x30     # 1.53 A: above the running current, below the current into the stop


def wait_idle(chain, limit_s=60.0):
    waited = 0.0
    while not chain.busy_pin(0):
        chain.advance(seconds=0.001)
        waited += 0.001
        if waited > limit_s:
            raise AssertionError(f"still busy after {limit_s} s")


def switch_homing(checks):
    chain = l6470emu.Chain("L6470", record=True)
    chain.get_status(0)
    chain.set_param(0, Reg.CONFIG, chain.get_param(0, Reg.CONFIG) | SW_MODE)
    chain.attach_axis(0, f"start={START},stops=-6400..,switch=home@0")
    chain.go_until(0, copy_to_mark=False, forward=False, speed=round(200 * 2**28 / l6470emu.TICKS_PER_SECOND))
    wait_idle(chain)
    status = chain.get_status(0)
    axis = chain.axis(0)
    print(f"switch: GoUntil stopped at {axis['position']}, home switch {axis['switches']['home']}, SW_EVN {status.SW_EVN}")
    checks.append((axis["switches"]["home"] and status.SW_EVN, "GoUntil stops on the home switch (SW_EVN)"))
    chain.release_sw(0, copy_to_mark=False, forward=True)
    wait_idle(chain)
    axis = chain.axis(0)
    print(f"switch: ReleaseSW stopped at {axis['position']}, home switch {axis['switches']['home']}")
    checks.append((not axis["switches"]["home"] and 0 < axis["position"] <= 4,
                   "ReleaseSW stops just off the switch (within 4 microsteps)"))
    chain.reset_pos(0)
    home = axis["position"]
    chain.go_to(0, TARGET)
    wait_idle(chain)
    true = chain.axis(0)["position"]
    print(f"switch: GoTo({TARGET}): ABS_POS {chain.position(0)}, true position {true} = home {home} + {true - home}")
    checks.append((chain.position(0) == TARGET and true - home == TARGET, "GoTo ends TARGET from home"))
    return chain


def stall_homing(checks):
    chain = l6470emu.Chain("L6470", record=True)
    chain.get_status(0)
    chain.set_param(0, Reg.STALL_TH, STALL_TH)
    chain.attach_axis(0, f"start={START // 8},stops=0..")
    chain.run(0, False, round(120 * 2**28 / l6470emu.TICKS_PER_SECOND))
    polls = 0
    while True:
        chain.advance(seconds=0.01)
        polls += 1
        status = chain.get_status(0)
        if status.STEP_LOSS_A or status.STEP_LOSS_B:
            break
        if polls > 1000:
            raise AssertionError("no stall within 10 s")
    chain.hard_stop(0)
    axis = chain.axis(0)
    print(f"stall: STEP_LOSS after {polls * 10} ms, true position {axis['position']} at the stop {axis['at_stop']}, "
          f"lost {axis['lost_steps']} microsteps")
    checks.append((axis["at_stop"] and axis["position"] == 0, "the stall is seen with the rotor at the hard stop"))
    chain.reset_pos(0)
    chain.go_to(0, TARGET)
    wait_idle(chain)
    true = chain.axis(0)["position"]
    print(f"stall: GoTo({TARGET}): ABS_POS {chain.position(0)}, true position {true}")
    # The rotor re-synchronises to the commanded electrical phase: within 2 full steps (256 microsteps).
    checks.append((chain.position(0) == TARGET and abs(true - TARGET) <= 256,
                   "GoTo after sensorless homing ends within 2 full steps of TARGET on the carriage"))
    return chain


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--plot", help="draw the switch homing into this .png or .svg (needs python3-matplotlib)")
    args = parser.parse_args()
    checks = []
    chain = switch_homing(checks)
    stall_homing(checks)
    ok = True
    for good, what in checks:
        print(f"  {'ok  ' if good else 'FAIL'} {what}")
        ok = ok and bool(good)
    if args.plot:
        from l6470emu import plot as pictures
        if pictures.available():
            print(f"plot: {pictures.plot(chain, args.plot, title='switch homing: GoUntil, ReleaseSW, ResetPos, GoTo')}")
        else:
            print(f"plot skipped: {pictures.MATPLOTLIB_MISSING}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
