"""Chain: the reference host's commands, registers by enum / name / address, and the errors
a wrong argument gives (ValueError / TypeError naming the argument, never a crash)."""
import pytest

import l6470emu
from l6470emu import Reg


def test_a_new_chain_is_at_power_up_hiz_with_uvlo_latched():
    chain = l6470emu.Chain(["L6470", "L6480"])
    assert len(chain) == 2 and chain.variants == ["L6470", "L6480"] and chain.spec == "L6470,L6480"
    assert chain.get_status(0) == 0x7C03
    assert chain.get_status(0) == 0x7E03  # GetStatus cleared UVLO
    assert chain.now == chain.now_seconds * l6470emu.TICKS_PER_SECOND > 0


def test_chips_may_be_a_list_a_description_or_a_count():
    assert l6470emu.Chain("2xL6470,L6480").variants == ["L6470", "L6470", "L6480"]
    assert l6470emu.Chain(["3*L6472"]).spec == "3*L6472"
    assert l6470emu.Chain(3).spec == "3*L6470"
    assert l6470emu.Chain().spec == "L6470"
    assert l6470emu.Chain(["powerstep01"]).variants == ["powerSTEP01"]


@pytest.mark.parametrize("chips, message", [
    (["L6471"], "unknown chip variant"),
    ([], "at least one chip"),
    ("257", "at most 256"),
    (["L6470, L6480"], "is not one item"),
    (0, "out of range"),
])
def test_a_wrong_chain_description_is_a_value_error(chips, message):
    with pytest.raises(ValueError, match=message):
        l6470emu.Chain(chips)


def test_a_chain_description_of_the_wrong_type_is_a_type_error():
    with pytest.raises(TypeError):
        l6470emu.Chain([1, 2])
    with pytest.raises(TypeError):
        l6470emu.Chain(3.5)


def test_move_runs_in_virtual_time_and_ends_on_target():
    chain = l6470emu.Chain(3)
    chain.move(2, forward=True, n_step=3200)
    assert not chain.busy_pin(2) and chain.status(2).BUSY
    chain.advance(seconds=0.5)
    assert chain.get_param(2, Reg.ABS_POS) == 3200 and chain.busy_pin(2)
    assert chain.get_param(0, "ABS_POS") == 0
    chain.move(2, False, 6400)
    chain.advance(seconds=1)
    assert chain.position(2) == -3200
    assert chain.get_param(2, 0x01) == (1 << 22) - 3200  # GetParam answers the raw 22 bits


def test_registers_by_enum_name_or_address_and_the_table_in_force():
    chain = l6470emu.Chain(["L6470", "L6480"])
    assert chain.get_param(0, Reg.CONFIG) == 0x2E88
    assert chain.get_param(1, "config") == 0x2C88
    assert chain.get_param(1, 0x1A) == 0x2C88
    chain.set_param(0, Reg.MAX_SPEED, 0x20)
    assert chain.peek(0, Reg.MAX_SPEED) == 0x20
    assert [r.name for r in chain.registers(1)][-4:] == ["GATECFG1", "GATECFG2", "CONFIG", "STATUS"]
    acc = next(r for r in l6470emu.register_table("L6470") if r.reg == Reg.ACC)
    assert (acc.address, acc.bits, acc.reset, acc.access, acc.spi_bytes) == (0x05, 12, 0x08A, "WS", 2)
    assert "TVAL_HOLD" in [r.name for r in l6470emu.register_table("powerSTEP01", current_mode=True)]


def test_the_register_enum_holds_every_name_of_the_variant_tables():
    names = set()
    for v in l6470emu.variants():
        names |= {r.name for r in l6470emu.register_table(v)}
    names |= {r.name for r in l6470emu.register_table("powerSTEP01", current_mode=True)}
    assert names == set(Reg.__members__)


def test_register_mistakes_name_the_chip_and_the_register():
    chain = l6470emu.Chain(["L6470", "L6480"])
    with pytest.raises(ValueError, match=r"chip 0 \(L6470\) has no register GATECFG1"):
        chain.get_param(0, Reg.GATECFG1)
    with pytest.raises(ValueError, match=r"chip 0 \(L6470\) has no register at address 26"):
        chain.get_param(0, 0x1A)
    with pytest.raises(ValueError, match="unknown register"):
        chain.get_param(0, "ABS_PSO")
    with pytest.raises(ValueError, match="out of range"):
        chain.get_param(0, 0x20)
    with pytest.raises(TypeError):
        chain.get_param(0, 1.5)


def test_values_out_of_their_field_are_value_errors():
    chain = l6470emu.Chain()
    with pytest.raises(ValueError, match="n_step"):
        chain.move(0, True, 1 << 22)
    with pytest.raises(ValueError, match="speed"):
        chain.run(0, True, 1 << 20)
    with pytest.raises(ValueError, match="value of ACC"):
        chain.set_param(0, Reg.ACC, 0x10000)
    with pytest.raises(ValueError, match="out of range"):
        chain.set_param(0, Reg.ACC, -1)
    with pytest.raises(ValueError, match="out of range"):
        chain.move(0, True, 1 << 80)  # beyond any C integer: still a ValueError
    chain.set_param(0, Reg.ABS_POS, -5)   # positions take negative numbers
    assert chain.position(0) == -5


def test_a_chip_index_outside_the_chain_is_a_value_error():
    chain = l6470emu.Chain(2)
    with pytest.raises(ValueError, match=r"chip 2 is not in the chain: it has 2 chips \(0..1\)"):
        chain.get_status(2)
    with pytest.raises(ValueError, match="chip -1"):
        chain.move(-1, True, 1)
    with pytest.raises(TypeError):
        chain.hard_stop("0")


def test_every_reference_host_command_reaches_the_chip():
    chain = l6470emu.Chain()
    chain.get_status(0)
    chain.run(0, True, 0x4000)
    chain.advance(seconds=0.2)
    assert chain.status(0).mot_status in ("ACC", "CONST")
    chain.soft_stop(0)
    chain.advance(seconds=0.5)
    assert chain.status(0).mot_status == "STOPPED" and not chain.status(0).HiZ
    chain.set_param(0, Reg.MARK, 1000)
    chain.go_mark(0)
    chain.advance(seconds=1)
    assert chain.position(0) == 1000
    chain.go_home(0)
    chain.advance(seconds=1)
    assert chain.position(0) == 0
    chain.go_to(0, -2000)
    chain.advance(seconds=1)
    chain.goto(0, 500)
    chain.advance(seconds=1)
    assert chain.position(0) == 500
    chain.go_to_dir(0, False, 100)
    chain.advance(seconds=1)
    assert chain.position(0) == 100
    chain.reset_pos(0)
    assert chain.position(0) == 0
    chain.hard_hiz(0)
    assert chain.status(0).HiZ
    chain.run(0, False, 0x2000)
    chain.hard_stop(0)
    assert chain.status(0).mot_status == "STOPPED"
    chain.soft_hiz(0)
    chain.advance(seconds=0.1)
    assert chain.status(0).HiZ
    chain.set_param(0, Reg.ACC, 0x100)
    chain.reset_device(0)
    assert chain.peek(0, Reg.ACC) == 0x08A
    chain.nop(0)
    assert chain.send(0, b"\xD0\x00\x00") == b"\x00\x7C\x03"  # a reset latches UVLO again


def test_go_until_stops_at_the_switch_and_release_sw_leaves_it():
    chain = l6470emu.Chain()
    chain.go_until(0, copy_to_mark=False, forward=False, speed=0x2000)
    chain.advance(seconds=0.3)
    chain.set_sw_pin(0, False)  # the homing switch closes
    chain.advance(seconds=0.5)
    status = chain.get_status(0)
    assert status.SW_EVN and status.SW_F and status.mot_status == "STOPPED"
    assert chain.position(0) == 0  # GoUntil without ACT resets ABS_POS
    chain.release_sw(0, False, True)
    chain.advance(seconds=0.1)
    chain.set_sw_pin(0, True)
    chain.advance(seconds=0.5)
    assert not chain.status(0).SW_F and chain.sw_pin(0)


def test_step_clock_mode_steps_on_stck_rising_edges():
    chain = l6470emu.Chain()
    chain.step_clock(0, True)
    assert chain.status(0).SCK_MOD
    for _ in range(5):
        chain.set_stck_pin(0, True)
        chain.set_stck_pin(0, False)
    assert chain.position(0) == 5


def test_the_chips_diagnostics_are_kept_for_the_test():
    chain = l6470emu.Chain(check="off")  # the chip's own reaction, not the sanitizer's
    chain.frame(b"\xEB")  # reserved opcode
    status = chain.get_status(0)
    assert status.WRONG_CMD
    diagnostics = chain.take_diagnostics()
    assert [d.kind for d in diagnostics] == ["wrong_cmd"] and diagnostics[0].chip == 0
    assert "0xEB" in diagnostics[0].message
    assert chain.take_diagnostics() == []


def test_dump_lists_every_register():
    dump = l6470emu.Chain(["L6480"]).dump(0)
    assert "GATECFG1" in dump and "STATUS" in dump
