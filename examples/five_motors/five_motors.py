"""Five motors on one daisy chain: each is told, in the same CS frames, to move 10 000
half-steps (STEP_MODE half step) at up to 900 half-steps/s, each with its own ramp. At 4 s
motor 3 is soft-stopped; at 7 s an emergency stop (HardHiZ to every chip in one frame) stops
the rest where they are. The positions are read back in the same frames and printed.

Units: ABS_POS in half-steps (STEP_SEL = 1). Speeds: MAX_SPEED 29 = 442.5 full step/s =
885 half-steps/s, the register's closest value not above 900 half-steps/s (its unit is
15.26 full step/s).

    PYTHONPATH=build/python /usr/bin/python3 examples/five_motors/five_motors.py --plot five_motors.png

Exit status 0 when every motor did that, 1 when not.
"""
import argparse
import sys

import l6470emu
from l6470emu import Reg

CHIPS = 5
HALF_STEPS = 10_000
MAX_SPEED = 29                          # 442.5 full step/s = 885 half-steps/s
RAMPS = [0x05, 0x0A, 0x14, 0x28, 0x50]  # ACC = DEC per chip: 73, 146, 291, 582, 1164 full step/s²
SOFT_STOPPED = 3
SOFT_STOP_AT_S = 4.0
EMERGENCY_AT_S = 7.0

MOVE_FWD, GET_ABS_POS, HARD_HIZ, SOFT_STOP, NOP = 0x41, 0x21, 0xA8, 0xB0, 0x00


def same_frames(chain, commands):
    """Sends one command per chip (a list of byte lists, chip 0 first) in shared CS frames:
    frame j carries byte j of every chip's command (NOP where a command is shorter).
    Returns each chip's answer bytes."""
    length = max(len(c) for c in commands)
    answers = [[] for _ in commands]
    for j in range(length):
        frame = bytes(c[j] if j < len(c) else NOP for c in commands)
        reply = chain.frame(frame)
        for k in range(len(commands)):
            answers[k].append(reply[k])
    return answers


def positions(chain):
    """ABS_POS of every chip, read in the same frames: GetParam(ABS_POS) then 3 answer bytes."""
    answers = same_frames(chain, [[GET_ABS_POS, NOP, NOP, NOP]] * CHIPS)
    out = []
    for a in answers:
        v = a[1] << 16 | a[2] << 8 | a[3]
        out.append(v - (1 << 22) if v & 0x200000 else v)
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--plot", help="draw the run into this .png or .svg (needs python3-matplotlib)")
    args = parser.parse_args()

    chain = l6470emu.Chain(f"{CHIPS}xL6470", record=True)
    for k in range(CHIPS):
        chain.get_status(k)
        chain.set_param(k, Reg.STEP_MODE, 0x01)  # half step (written while the bridges are off)
        chain.set_param(k, Reg.MAX_SPEED, MAX_SPEED)
        chain.set_param(k, Reg.ACC, RAMPS[k])
        chain.set_param(k, Reg.DEC, RAMPS[k])
    n = HALF_STEPS
    same_frames(chain, [[MOVE_FWD, n >> 16 & 0x3F, n >> 8 & 0xFF, n & 0xFF]] * CHIPS)
    start = chain.now_seconds

    chain.advance(seconds=start + SOFT_STOP_AT_S - chain.now_seconds)
    same_frames(chain, [[SOFT_STOP] if k == SOFT_STOPPED else [NOP] for k in range(CHIPS)])
    chain.advance(seconds=1.0)
    soft_stopped_at = chain.position(SOFT_STOPPED)
    soft_stop_done = chain.busy_pin(SOFT_STOPPED) and chain.peek(SOFT_STOPPED, Reg.SPEED) == 0
    soft_stop_holds = not chain.status(SOFT_STOPPED).HiZ  # SoftStop keeps the bridges on

    chain.advance(seconds=start + EMERGENCY_AT_S - chain.now_seconds)
    moving_before = [chain.peek(k, Reg.SPEED) > 0 for k in range(CHIPS)]
    same_frames(chain, [[HARD_HIZ]] * CHIPS)
    stopped_at = positions(chain)
    chain.advance(seconds=1.0)
    final = positions(chain)

    print("chip  ACC=DEC  end position (half-steps)")
    for k in range(CHIPS):
        note = " soft-stopped at 4 s" if k == SOFT_STOPPED else ""
        print(f"{k:4}  0x{RAMPS[k]:03X}    {final[k]:6}{note}")

    others = [k for k in range(CHIPS) if k != SOFT_STOPPED]
    checks = [
        (soft_stop_done and soft_stop_holds, f"motor {SOFT_STOPPED} stopped within 1 s of its SoftStop, bridges on"),
        (final[SOFT_STOPPED] == soft_stopped_at, f"motor {SOFT_STOPPED} stayed where its SoftStop left it"),
        (all(moving_before[k] for k in others), "the others were still moving at the emergency stop"),
        (final == stopped_at, "after HardHiZ nothing moves any more"),
        (all(0 < p < HALF_STEPS for p in final), "no motor reached 10 000 half-steps"),
        (all(chain.status(k).HiZ and chain.busy_pin(k) for k in range(CHIPS)), "every bridge is off, BUSY released"),
        (all(final[a] < final[b] for a, b in zip(others, others[1:])), "a steeper ramp got further"),
    ]
    ok = True
    for good, what in checks:
        print(f"  {'ok  ' if good else 'FAIL'} {what}")
        ok = ok and good

    if args.plot:
        from l6470emu import plot as pictures
        if pictures.available():
            out = pictures.plot(chain, args.plot, position_unit=("half-steps", 1),
                                title="five motors: 10 000 half-steps each; SoftStop of 3 at 4 s, HardHiZ at 7 s")
            print(f"plot: {out}")
        else:
            print(f"plot skipped: {pictures.MATPLOTLIB_MISSING}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
