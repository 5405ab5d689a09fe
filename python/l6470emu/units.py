"""Register values in physical units and back, with each variant's own formulas.

The registers count in the chip's units: SPEED in 2^-28 step per 250 ns tick, ACC in 2^-40
step/tick², OCD_TH in 375 mA steps on the L6470 and 31.25 mV steps on the gate drivers, and so
on. This module converts both ways:

>>> from l6470emu import units
>>> units.speed_to_reg(200.0)                    # Run's SPD argument, or the SPEED register
13422
>>> units.reg_to_max_speed(0x041)
991.8212890625
>>> units.to_register("OCD_TH", 3000)            # mA on the L6470
7
>>> units.to_physical("OCD_TH", 7, variant="L6480")   # mV of V_DS on the L6480
250.0

Physical values are in the units `scale(name).unit` names: step/s, step/s², mA, mV, VS (KVAL:
a fraction of the supply, 0 to 255/256), s/step (BEMF slopes), µs, x (K_THERM) and VREG
(ADC_OUT). A physical value becomes the nearest register value (a tie goes to the larger);
one whose nearest value is out of range raises ValueError, or with saturate=True gives the
nearest end. Register values convert exactly: every scale's step is a power-of-two fraction,
so to_physical() returns the exact value as a float and to_physical_exact() as a Fraction.
ACC = 0xFFF is infinite acceleration on the variants that have it: math.inf both ways.

Names are registers (MAX_SPEED, TVAL_RUN, ...), "SPD" (the Run/GoUntil argument, SPEED's
scale), or the fields of T_FAST (TOFF_FAST, FAST_STEP), whose value is the field alone. MIN_SPEED
converts its bits 11..0 (LSPD_OPT, bit 12, is not part of the speed) and FS_SPD its bits 9..0
(BOOST_MODE is bit 10 on the gate drivers). Where a formula rests on one source or the sources
disagree, scale(name).note says so.
"""
from __future__ import annotations

import math
from fractions import Fraction
from typing import List, NamedTuple, Union

from . import _l6470emu

__all__ = [
    "Scale",
    "acc_to_reg",
    "dec_to_reg",
    "fs_spd_to_reg",
    "max_speed_to_reg",
    "min_speed_to_reg",
    "reg_to_acc",
    "reg_to_dec",
    "reg_to_fs_spd",
    "reg_to_max_speed",
    "reg_to_min_speed",
    "reg_to_speed",
    "scale",
    "scales",
    "speed_to_reg",
    "to_physical",
    "to_physical_exact",
    "to_register",
]

Number = Union[int, float, Fraction]


class Scale(NamedTuple):
    """How one register (or field) maps onto a physical quantity:
    physical = (n + offset) * lsb, with n = (register value >> shift) & (2**bits - 1)."""

    name: str
    """The register or field name ("MAX_SPEED", "TOFF_FAST")."""
    register: str
    """The register the field lives in ("T_FAST" for TOFF_FAST)."""
    shift: int
    """The field's lowest bit."""
    bits: int
    """The field's width."""
    offset: Fraction
    """Added to n before scaling: 0, 1/2 (FS_SPD) or 1 (thresholds counted from one step)."""
    lsb: Fraction
    """One step of n in `unit`, exactly."""
    unit: str
    """"step/s", "step/s²", "mA", "mV", "VS", "s/step", "µs", "x" or "VREG"."""
    top_is_infinite: bool
    """The largest value means infinite acceleration (ACC on the L6470, L6480, L6482, powerSTEP01)."""
    note: str
    """Where the formula is not a datasheet's own: "UNCONFIRMED: ...", "CONFLICT: ..."; else ""."""

    @property
    def max_value(self) -> int:
        """The largest field value."""
        return (1 << self.bits) - 1


def _scale_of(t: tuple) -> Scale:
    name, register, shift, bits, offset_halves, lsb_num, lsb_den, unit, top_is_infinite, note = t
    return Scale(name, register, shift, bits, Fraction(offset_halves, 2), Fraction(lsb_num, lsb_den), unit,
                 top_is_infinite, note)


def scale(name: str, variant: str = "L6470") -> Scale:
    """The scale of register or field `name` on `variant` (ValueError naming the near miss, or
    the variants that have the register, when there is none)."""
    return _scale_of(_l6470emu._unit_scale(variant, name))


def scales(variant: str = "L6470") -> List[Scale]:
    """Every scale of `variant`, in address order (the powerSTEP01's current-mode ones last)."""
    return [_scale_of(t) for t in _l6470emu._unit_scales(variant)]


def to_physical_exact(name: str, value: int, variant: str = "L6470") -> Union[Fraction, float]:
    """The exact physical value of register (field) value `value`: a Fraction, or math.inf for
    ACC = 0xFFF where it selects infinite acceleration."""
    num, den, infinite = _l6470emu._to_physical(variant, name, value)
    return math.inf if infinite else Fraction(num, den)


def to_physical(name: str, value: int, variant: str = "L6470") -> float:
    """The physical value of register (field) value `value`, in scale(name).unit. Exact: every
    value is a power-of-two fraction a float holds exactly."""
    return float(to_physical_exact(name, value, variant))


def to_register(name: str, physical: Number, variant: str = "L6470", saturate: bool = False) -> int:
    """The register (field) value whose physical value is nearest to `physical` (in
    scale(name).unit; a tie goes up). Out of range: ValueError, or the nearest end with
    saturate=True. to_register(n, to_physical(n)) is n for every value of every register."""
    if isinstance(physical, bool) or not isinstance(physical, (int, float, Fraction)):
        raise TypeError(f"physical: a number is needed, not {type(physical).__name__}")
    return _l6470emu._to_register(variant, name, float(physical), bool(saturate))


def speed_to_reg(step_per_s: Number, saturate: bool = False) -> int:
    """SPEED / Run's SPD for a speed in full steps per second (2^-28 step/tick: 200 -> 13422)."""
    return to_register("SPEED", step_per_s, saturate=saturate)


def reg_to_speed(value: int) -> float:
    """The speed in step/s of a SPEED value (or Run's SPD argument)."""
    return to_physical("SPEED", value)


def acc_to_reg(step_per_s2: Number, variant: str = "L6470", saturate: bool = False) -> int:
    """ACC for an acceleration in step/s² (2^-40 step/tick²; math.inf -> 0xFFF where it means
    infinite acceleration)."""
    return to_register("ACC", step_per_s2, variant, saturate)


def reg_to_acc(value: int, variant: str = "L6470") -> float:
    """The acceleration in step/s² of an ACC value (math.inf for 0xFFF where it is infinite)."""
    return to_physical("ACC", value, variant)


def dec_to_reg(step_per_s2: Number, saturate: bool = False) -> int:
    """DEC for a deceleration in step/s²."""
    return to_register("DEC", step_per_s2, saturate=saturate)


def reg_to_dec(value: int) -> float:
    """The deceleration in step/s² of a DEC value."""
    return to_physical("DEC", value)


def max_speed_to_reg(step_per_s: Number, saturate: bool = False) -> int:
    """MAX_SPEED for a speed in step/s (2^-18 step/tick, 15.26 step/s per step)."""
    return to_register("MAX_SPEED", step_per_s, saturate=saturate)


def reg_to_max_speed(value: int) -> float:
    """The speed in step/s of a MAX_SPEED value."""
    return to_physical("MAX_SPEED", value)


def min_speed_to_reg(step_per_s: Number, saturate: bool = False) -> int:
    """MIN_SPEED's bits 11..0 for a speed in step/s (2^-24 step/tick); LSPD_OPT (bit 12) is the caller's."""
    return to_register("MIN_SPEED", step_per_s, saturate=saturate)


def reg_to_min_speed(value: int) -> float:
    """The speed in step/s of MIN_SPEED's bits 11..0 (mask LSPD_OPT, bit 12, off first)."""
    return to_physical("MIN_SPEED", value)


def fs_spd_to_reg(step_per_s: Number, saturate: bool = False) -> int:
    """FS_SPD's bits 9..0 for a threshold speed in step/s ((FS_SPD + 0.5) * 2^-18 step/tick)."""
    return to_register("FS_SPD", step_per_s, saturate=saturate)


def reg_to_fs_spd(value: int) -> float:
    """The threshold speed in step/s of FS_SPD's bits 9..0 (mask BOOST_MODE, bit 10, off first)."""
    return to_physical("FS_SPD", value)
