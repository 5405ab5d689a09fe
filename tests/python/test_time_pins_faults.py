"""Virtual time (advance, next_event), the pins (SW, STCK, STBY/RST in; BUSY, FLAG out) and
the backdoor faults, each reaching STATUS and FLAG as the chip would."""
import pytest

import l6470emu
from l6470emu import Reg, Thermal


def test_time_moves_only_when_advanced():
    chain = l6470emu.Chain()
    start = chain.now
    chain.advance(ticks=4000)
    assert chain.now == start + 4000
    chain.advance(seconds=0.25)
    assert chain.now == start + 4000 + 1_000_000
    chain.advance_to(chain.now + 1)
    assert chain.now_seconds == pytest.approx(chain.now / 4e6)


@pytest.mark.parametrize("kwargs, message", [
    ({}, "exactly one"), ({"seconds": 1, "ticks": 1}, "exactly one"),
    ({"seconds": -1}, "not a time"), ({"seconds": float("nan")}, "not a time"), ({"ticks": -1}, "out of range"),
])
def test_advance_needs_one_non_negative_amount(kwargs, message):
    with pytest.raises(ValueError, match=message):
        l6470emu.Chain().advance(**kwargs)


def test_time_never_goes_back():
    chain = l6470emu.Chain()
    chain.advance(ticks=100)
    with pytest.raises(ValueError, match="in the past"):
        chain.advance_to(50)


def test_next_event_is_none_when_idle_and_the_profile_phase_while_moving():
    chain = l6470emu.Chain()
    assert chain.next_event() is None
    chain.move(0, True, 3200)
    event = chain.next_event()
    assert event is not None and event > chain.now
    while (event := chain.next_event()) is not None:
        chain.advance_to(event)
    assert chain.position(0) == 3200 and chain.busy_pin(0)


def test_flag_follows_the_latched_alarms():
    chain = l6470emu.Chain()
    assert not chain.flag_pin(0)  # UVLO latched at power-up
    chain.get_status(0)
    assert chain.flag_pin(0)
    chain.set_thermal(0, "warning")
    assert not chain.flag_pin(0) and chain.status(0).TH_WRN
    chain.set_thermal(0, Thermal.normal)
    chain.get_status(0)
    assert chain.flag_pin(0)


@pytest.mark.parametrize("variant, flag", [("L6470", "STEP_LOSS_A"), ("L6480", "STALL_A")])
def test_stall_flags_carry_the_variants_own_names(variant, flag):
    chain = l6470emu.Chain([variant])
    chain.set_stall(0, "A", True)
    status = chain.status(0)
    assert getattr(status, flag) and flag in status.names
    chain.set_stall(0, l6470emu.Bridge.B, True)
    assert len({"STEP_LOSS_B", "STALL_B"} & chain.status(0).names) == 1


def test_overcurrent_undervoltage_and_the_generic_fault_call():
    chain = l6470emu.Chain(["L6480"])
    chain.get_status(0)
    chain.set_overcurrent(0, True)
    assert chain.status(0).OCD
    chain.set_undervoltage(0, True)
    assert chain.status(0).UVLO
    chain.set_adc_undervoltage(0, True)
    assert chain.status(0).UVLO_ADC
    chain.fault(0, "THERMAL", "bridge_shutdown")
    assert chain.status(0).TH_BRIDGE_SHUTDOWN
    chain.fault(0, l6470emu.Fault.ADCIN, 17)
    assert chain.get_param(0, Reg.ADC_OUT) == 17
    chain.fault(0, "ocd", False)
    chain.set_undervoltage(0, False)
    chain.set_adc_undervoltage(0, False)
    chain.set_thermal(0, 0)
    chain.get_status(0)
    assert not ({"OCD", "UVLO", "UVLO_ADC"} & chain.get_status(0).names)


def test_the_adc_input_reads_back_as_adc_out():
    chain = l6470emu.Chain()
    chain.set_adc_input(0, 31)
    assert chain.get_param(0, Reg.ADC_OUT) == 31
    with pytest.raises(ValueError, match="code"):
        chain.set_adc_input(0, 32)


@pytest.mark.parametrize("call, error, message", [
    (lambda c: c.set_thermal(0, "hot"), ValueError, "not normal, warning"),
    (lambda c: c.set_thermal(0, 4), ValueError, "out of range"),
    (lambda c: c.set_stall(0, "C", True), ValueError, "not A or B"),
    (lambda c: c.fault(0, "FIRE", 1), ValueError, "not UVLO"),
    (lambda c: c.fault(0, "OCD", 2), ValueError, "out of range"),
    (lambda c: c.set_sw_pin(0, 2), ValueError, "level"),
    (lambda c: c.set_stall(0, 1, True), TypeError, "bridge"),
])
def test_wrong_physical_world_arguments_are_refused(call, error, message):
    with pytest.raises(error, match=message):
        call(l6470emu.Chain())


def test_stby_rst_low_holds_the_chip_in_reset_with_spi_silent():
    chain = l6470emu.Chain(2, check_allow=["STANDBY_BYTE"])  # GetStatus to a chip in standby, knowingly
    chain.move(1, True, 1000)
    chain.set_stby_rst_pin(1, False)
    assert chain.frame(b"\xD0\xD0") == b"\x00\x00" and chain.status(1) == 0
    chain.set_stby_rst_pin(1, True)  # rising edge: power-up state
    assert chain.get_status(1) == 0x7C03 and chain.position(1) == 0


def test_the_one_shot_faults_act_once():
    chain = l6470emu.Chain(["L6470", "L6470"])
    chain.get_status(0)
    chain.set_param(0, Reg.KVAL_RUN, 0x55)
    chain.fault(0, l6470emu.Fault.POWER_CYCLE)
    assert chain.get_param(0, Reg.KVAL_RUN) == 0x29 and chain.status(0).UVLO
    chain.frame(bytes([0x2A, 0x2A]))  # GetParam(KVAL_RUN): the answers wait in the registers
    chain.fault(1, "MISO_FLIP")  # bit 7 by default
    assert list(chain.frame(bytes(2))) == [0x29, 0x29 ^ 0x80]
    chain.fault(0, "LOST_FRAME")
    chain.frame(bytes([0x0A, 0x0A]))  # SetParam(KVAL_RUN): chip 0 misses it
    chain.frame(bytes([0x00, 0x44]))
    assert chain.get_param(0, Reg.KVAL_RUN) == 0x29 and chain.get_param(1, Reg.KVAL_RUN) == 0x44
