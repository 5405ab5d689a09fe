"""l6470emu.units: register values in physical units and back, per variant, exactly."""
import math
from fractions import Fraction

import pytest

import l6470emu
from l6470emu import units


def test_the_users_hand_computation_comes_out():
    assert units.speed_to_reg(200.0) == 13422
    assert units.reg_to_speed(13422) == pytest.approx(200.0034, abs=1e-4)
    assert units.reg_to_max_speed(0x041) == 991.8212890625
    assert units.max_speed_to_reg(991.8212890625) == 0x041
    assert units.reg_to_acc(0x08A) == pytest.approx(2008.16, abs=0.01)
    assert units.acc_to_reg(2008.16) == 0x08A
    assert units.dec_to_reg(units.reg_to_dec(0x123)) == 0x123
    assert units.min_speed_to_reg(units.reg_to_min_speed(0xFFF)) == 0xFFF
    assert units.reg_to_fs_spd(0x027) == pytest.approx(602.7, abs=0.05)
    assert units.fs_spd_to_reg(602.7) == 0x027


def test_each_variant_has_its_own_units():
    assert units.to_register("OCD_TH", 3000) == 7  # 375 mA steps on the L6470
    assert units.to_physical("OCD_TH", 7, variant="L6480") == 250.0  # 31.25 mV steps of V_DS
    assert units.to_physical("TVAL_RUN", 127, variant="L6482") == 1000.0
    assert units.to_physical("KVAL_HOLD", 0x29, variant="powerSTEP01") == 41 / 256
    assert units.to_physical("TVAL_HOLD", 0x29, variant="powerSTEP01") == 42 * 7.8125  # the same address in current mode
    assert units.scale("TVAL_RUN", "L6472").note.startswith("UNCONFIRMED")
    assert units.scale("INT_SPEED").note.startswith("CONFLICT")
    s = units.scale("TOFF_FAST", "L6482")
    assert (s.register, s.shift, s.bits, s.unit) == ("T_FAST", 4, 4, "µs")
    assert units.to_physical("TOFF_FAST", (0x19 >> s.shift) & s.max_value, variant="L6482") == 4.0


def test_exact_values_are_fractions_and_infinite_acceleration_is_inf():
    assert units.to_physical_exact("SPEED", 1) == Fraction(15625, 2**20)
    assert units.to_physical_exact("ACC", 0xFFF) == math.inf
    assert units.acc_to_reg(math.inf) == 0xFFF
    assert units.reg_to_acc(0xFFF, variant="L6472") == pytest.approx(59590, abs=1)  # reserved there: a value
    assert units.to_register("MAX_SPEED", Fraction(15625, 1024) * 3) == 3


def test_every_value_of_every_scale_of_every_variant_round_trips():
    distinct = {}
    for variant in l6470emu.variants():
        for s in units.scales(variant):
            distinct.setdefault(s, variant)  # the same scale on several variants is checked once
    checked = 0
    for s, variant in distinct.items():
        for n in range(s.max_value + 1):
            assert units.to_register(s.name, units.to_physical(s.name, n, variant), variant) == n, (variant, s.name, n)
            checked += 1
    assert checked > 2**20


def test_rounding_goes_to_the_nearest_value_and_ties_go_up():
    lsb = 15625 / 1024
    assert units.max_speed_to_reg(12.49 * lsb) == 12
    assert units.max_speed_to_reg(12.5 * lsb) == 13
    assert units.max_speed_to_reg(12.51 * lsb) == 13
    assert units.to_register("OCD_TH", 200) == 0  # nearer 375 mA than nothing


def test_out_of_range_values_raise_or_saturate():
    with pytest.raises(ValueError, match=r"MAX_SPEED: 20000 step/s is above the largest value, 15609.7412109375 step/s \(0x3FF\)"):
        units.max_speed_to_reg(20000)
    assert units.max_speed_to_reg(20000, saturate=True) == 0x3FF
    assert units.speed_to_reg(-5, saturate=True) == 0
    with pytest.raises(ValueError, match="not a number"):
        units.speed_to_reg(math.nan, saturate=True)
    with pytest.raises(ValueError, match=r"MAX_SPEED value = 1024 is out of range 0..1023"):
        units.reg_to_max_speed(1024)


def test_bad_names_and_variants_say_what_was_meant():
    with pytest.raises(ValueError, match=r"unknown register 'MAX_SPED'; did you mean 'MAX_SPEED'\?"):
        units.to_register("MAX_SPED", 1)
    with pytest.raises(ValueError, match=r"L6470 has no TVAL_RUN \(a register of L6472, L6482, powerSTEP01\)"):
        units.to_register("TVAL_RUN", 1)
    with pytest.raises(ValueError, match=r"CONFIG has no physical unit"):
        units.scale("CONFIG")
    with pytest.raises(ValueError, match=r"did you mean L6470, L6472 or L6474\?"):
        units.scale("ACC", "L6471")
    with pytest.raises(TypeError):
        units.speed_to_reg("200")


def test_a_bad_variant_in_a_chain_says_what_was_meant_as_the_board_description_does():
    with pytest.raises(ValueError, match=r'chips: unknown chip variant "L6471" \(did you mean L6470, L6472 or L6474\? known: '):
        l6470emu.Chain(["L6471"])
    with pytest.raises(ValueError, match=r"did you mean powerSTEP01\?"):
        l6470emu.register_table("powrSTEP01")
