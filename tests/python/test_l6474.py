"""The L6474 from Python: a Chain of them answers its reset values and refuses a Move with
WRONG_CMD; STCK pulses move ABS_POS in the direction of its DIR pin; a Board has a DIR line per
chip after the usual five, driven like any other input; units know its TVAL."""
import pytest

import l6470emu
from l6470emu import Reg
from l6470emu.board import LINE_REQ_DIR_OUT


def pulses(chain, chip, n):
    for _ in range(n):
        chain.set_stck_pin(chip, True)
        chain.set_stck_pin(chip, False)


def test_a_chain_of_l6474s_answers_its_reset_values():
    chain = l6470emu.Chain(["L6474", "L6474"])
    resets = {Reg.ABS_POS: 0, Reg.EL_POS: 0, Reg.MARK: 0, Reg.TVAL: 0x29, Reg.T_FAST: 0x19, Reg.TON_MIN: 0x29,
              Reg.TOFF_MIN: 0x29, Reg.OCD_TH: 0x8, Reg.STEP_MODE: 0x07, Reg.ALARM_EN: 0xFF, Reg.CONFIG: 0x2E88,
              Reg.STATUS: 0xFC03}
    assert [r.name for r in chain.registers(1)] == ["ABS_POS", "EL_POS", "MARK", "TVAL", "T_FAST", "TON_MIN", "TOFF_MIN",
                                                    "ADC_OUT", "OCD_TH", "STEP_MODE", "ALARM_EN", "CONFIG", "STATUS"]
    for chip in (0, 1):
        for reg, value in resets.items():
            assert chain.get_param(chip, reg) == value, (chip, reg)


def test_a_move_is_no_command_and_sets_wrong_cmd():
    with pytest.raises(l6470emu.SanitizerError, match=r"byte 0x41: no such command on an L6474 \(Move on the others\)"):
        l6470emu.Chain(["L6474"]).move(0, True, 3200)  # check=error by default: the driver's mistake raises
    chain = l6470emu.Chain(["L6474"], check_allow=["WRONG_CMD"])
    chain.get_status(0)
    chain.move(0, True, 3200)
    status = chain.get_status(0)
    assert status.WRONG_CMD and status.HiZ and not status.NOTPERF_CMD
    assert chain.get_param(0, Reg.ABS_POS) == 0
    with pytest.raises(ValueError):
        chain.get_param(0, Reg.SPEED)  # no such register on an L6474


def test_stck_pulses_move_abs_pos_by_exactly_their_number_in_the_direction_of_dir():
    chain = l6470emu.Chain(["L6474"])
    chain.enable(0)
    assert not chain.get_status(0).HiZ
    chain.set_dir_pin(0, True)
    pulses(chain, 0, 100)
    assert chain.position(0) == 100 and chain.get_status(0).forward
    chain.set_dir_pin(0, False)
    pulses(chain, 0, 130)
    assert chain.position(0) == -30 and not chain.get_status(0).forward
    chain.disable(0)
    pulses(chain, 0, 10)  # in high impedance the pulses move nothing
    assert chain.position(0) == -30 and chain.get_status(0).HiZ


def test_step_mode_sixteenth_makes_a_pulse_an_eighth_of_el_pos_128():
    chain = l6470emu.Chain(["L6474"])
    chain.set_param(0, Reg.STEP_MODE, 0x8C)
    chain.enable(0)
    chain.set_dir_pin(0, 1)
    pulses(chain, 0, 16)
    assert chain.get_param(0, Reg.EL_POS) == 0x80 and chain.position(0) == 16


def test_a_board_brings_out_a_dir_line_per_chip_after_the_usual_five():
    board = l6470emu.Board("2xL6474")
    chip = board.gpiochip(0)
    assert chip.num_lines() == 12
    assert chip.find_line("DIR0").offset() == 10 and chip.find_line("DIR1").offset() == 11
    assert chip.find_line("STBY_RST1").offset() == 9
    assert board.line(1, "DIR").offset() == 11
    direction = chip.find_line("DIR1")
    direction.request("t", LINE_REQ_DIR_OUT, default_val=1)
    assert board.level(1, "DIR") == 1 and board.level(0, "DIR") == 0
    board.drive(1, "DIR", 0)
    assert board.level(1, "DIR") == 0
    with pytest.raises(ValueError, match="has no SW pin"):
        board.drive(0, "SW", 0)
    assert l6470emu.Board("2xL6470").gpiochip(0).num_lines() == 10  # no DIR lines without an L6474


def test_units_know_the_l6474s_tval():
    from l6470emu import units
    assert units.to_physical("TVAL", 0x29, variant="L6474") == pytest.approx(1312.5)
    assert units.to_register("TVAL", 1312.5, variant="L6474") == 0x29


def test_st_s_start_up_sequence_and_steps_break_no_sanitizer_rule():
    # ST's X-NUCLEO-IHM01A1 driver: every register written once (STEP_MODE with bits 7 and 3 set,
    # as it writes it), Disable, GetStatus, Enable, then steps on STCK. check=error raises on
    # any broken rule.
    board = l6470emu.Board("L6474")
    spi = board.spidev(0, 0)
    spi.mode = 3

    def send(*values):
        return [spi.xfer2([v])[0] for v in values]

    for command in ((0x01, 0, 0, 0), (0x02, 0, 0), (0x03, 0, 0, 0), (0x09, 0x08), (0x0E, 0x19), (0x0F, 0x29),
                    (0x10, 0x29), (0x13, 0x08), (0x16, 0x8C), (0x17, 0xFF), (0x18, 0x2E, 0x88), (0xA8,), (0xD0, 0, 0),
                    (0xB8,)):
        send(*command)
    board.drive(0, "DIR", 1)
    for _ in range(8):
        board.drive(0, "STCK", 1)
        board.drive(0, "STCK", 0)
    assert send(0x21, 0, 0, 0)[1:] == [0x00, 0x00, 0x08]
    status = send(0xD0, 0, 0)
    assert status[1] << 8 | status[2] == 0xFE12  # enabled, DIR forward, nothing latched


def test_a_recorded_l6474_run_replays_and_its_motion_is_the_pulses():
    chain = l6470emu.Chain(["L6474"], record=True)
    chain.enable(0)
    chain.set_dir_pin(0, True)
    for _ in range(24):
        chain.advance(seconds=0.001)
        pulses(chain, 0, 1)
    chain.set_dir_pin(0, False)
    for _ in range(4):
        chain.advance(seconds=0.001)
        pulses(chain, 0, 1)
    native = chain.trace.to_native()
    assert " pin 0 DIR 1\n" in native and " pin 0 DIR 0\n" in native
    assert [e.pin for e in chain.trace if e.kind == "pin" and e.pin == "DIR"] == ["DIR", "DIR"]
    m = l6470emu.motion(chain.trace, end=chain.now_seconds)
    c = m.chips[0]
    assert c.variant == "L6474" and c.microsteps_per_step == 16  # STEP_SEL 7 acts as 1/16
    assert c.abs_pos[-1] == 20 and max(c.abs_pos) == 24
    assert [x.name for x in c.commands] == ["Enable"]
    assert all(c.busy)  # no BUSY pin: nothing pulls it low
    assert l6470emu.replay(chain.trace).matched
