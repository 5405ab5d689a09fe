"""Status: STATUS as an int with its flags by datasheet name, decoded by the chip's own
layout (core/status.hpp's describe_status), so variants differ where their STATUS does."""
import pickle

import pytest

import l6470emu


def test_status_is_an_int_with_named_flags():
    status = l6470emu.Chain().get_status(0)
    assert status == 0x7C03 and isinstance(status, int) and hex(status) == "0x7c03"
    assert status.HiZ and status.UVLO and not status.BUSY and not status.OCD
    assert status.mot_status == "STOPPED" and not status.forward
    assert "UVLO" in status and status.names == {"HiZ", "REV", "STOPPED", "UVLO"}
    assert repr(status) == "Status(0x7C03: HiZ REV STOPPED UVLO)"
    assert status.variant == "L6470"


def test_command_errors_read_as_each_variant_reports_them():
    chain = l6470emu.Chain(["L6470", "L6480"], check_allow=["WRONG_CMD"])
    chain.frame(b"\xEB\xEB")
    assert chain.status(0).WRONG_CMD and not chain.status(0).CMD_ERROR
    assert chain.status(1).CMD_ERROR and not chain.status(1).WRONG_CMD


def test_an_unknown_flag_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no flag 'UVL0'"):
        l6470emu.Chain().status(0).UVL0


def test_status_survives_pickling():
    status = l6470emu.Chain().status(0)
    again = pickle.loads(pickle.dumps(status))
    assert again == status and again.names == status.names and repr(again) == repr(status)
