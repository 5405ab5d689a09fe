"""The axis from Python: Chain and Board (and so the l6470_chain and l6470_board fixtures) attach
an axis, read its true position, change its load and place switches."""
import pytest

import l6470emu
from l6470emu import Reg


def test_a_chain_attaches_an_axis_reads_the_true_position_and_places_a_switch(l6470_chain):
    l6470_chain.get_status(0)
    l6470_chain.attach_axis(0, "start=1000")
    assert l6470_chain.axis(0)["position"] == 1000
    l6470_chain.move(0, True, 640)
    l6470_chain.advance(seconds=1)
    assert l6470_chain.axis(0)["position"] == 1640
    l6470_chain.attach_axis(0, "switch=limit@2000:above")  # placed later: the rotor stays put
    axis = l6470_chain.axis(0)
    assert axis["position"] == 1640 and axis["switches"] == {"limit": False}
    l6470_chain.move(0, True, 640)
    l6470_chain.advance(seconds=1)
    assert l6470_chain.axis(0)["switches"]["limit"] and not l6470_chain.sw_pin(0)


def test_the_load_changes_at_runtime_and_a_stop_holds_the_rotor(l6470_chain):
    l6470_chain.get_status(0)
    l6470_chain.attach_axis(0, "stops=0..")
    l6470_chain.set_load(0, "load=500,friction=0.01")
    assert "load=500" in l6470_chain.axis(0)["spec"]
    l6470_chain.move(0, False, 1280)  # into the stop at 0
    l6470_chain.advance(seconds=1)
    axis = l6470_chain.axis(0)
    assert axis["position"] >= 0 and l6470_chain.position(0) == -1280  # commanded past the stop, never through it


def test_an_axis_error_names_the_item(l6470_chain):
    with pytest.raises(ValueError, match="axis"):
        l6470_chain.attach_axis(0, "stepz=200")
    with pytest.raises(ValueError, match="no axis"):
        l6470_chain.axis(0)


def test_a_board_attaches_an_axis_whose_switch_stops_the_motor(l6470_board):
    l6470_board.attach_axis(0, "start=500,switch=home@0")
    spi = l6470_board.spidev(0, 0)
    spi.mode = 3
    for byte in (0x40, 0x00, 0x02, 0x00):  # Move 512 reverse
        spi.xfer2([byte])
    l6470_board.advance(1.0)
    # SW_MODE 0: the closing switch stops the motor hard, on the switch
    axis = l6470_board.axis(0)
    assert -4 <= axis["position"] <= 0 and axis["switches"]["home"]


def test_a_load_change_is_a_load_event_of_the_recording_and_replays(tmp_path):
    # A Board's description (axis included) heads the recording; a Chain's axis is an event.
    board = l6470emu.Board("L6470", options="axis.0=stops=-100000..100000", trace_path=tmp_path / "load.trace")
    spi = board.spidev(0, 0)
    spi.mode = 3
    for byte in (0x51, 0x00, 0x20, 0x00):  # Run forward at 0x2000
        spi.xfer2([byte])
    board.advance(0.05)
    board.set_load(0, "load=2000,friction=0.05")
    board.advance(0.05)
    [spi.xfer2([b]) for b in (0xD0, 0, 0)]
    board.close()
    text = (tmp_path / "load.trace").read_text()
    assert " load 0 " in text, text
    result = l6470emu.replay(tmp_path / "load.trace")
    assert result.matched and result.pin_mismatches == 0, result

    chain = l6470emu.Chain("L6470", record=tmp_path / "chain.trace")
    chain.attach_axis(0, "stops=-100000..100000")
    chain.set_load(0, "load=2000")
    chain.close()
    assert " load 0 " in (tmp_path / "chain.trace").read_text()


def test_an_axis_attached_while_a_chain_records_is_an_event_and_its_switch_replays(tmp_path):
    chain = l6470emu.Chain("L6470", record=tmp_path / "home.trace")
    chain.get_status(0)
    chain.attach_axis(0, "start=2560,switch=home@0")  # after the recording began
    chain.go_until(0, copy_to_mark=False, forward=False, speed=0x2000)
    chain.advance(seconds=2)
    assert chain.axis(0)["switches"]["home"] and chain.busy_pin(0)
    chain.close()
    text = (tmp_path / "home.trace").read_text()
    assert "\nboard chips=L6470\n" in text  # a Chain's own board lines: its chips and checks
    assert " axis 0 start=2560,switch=home@0:below:no\n" in text
    assert " pin 0 SW 0 axis\n" in text  # the switch closing, observed at its tick
    result = l6470emu.replay(tmp_path / "home.trace")
    assert result.matched and result.pin_checks > 3, result
    # Without the axis event the carriage never reaches the switch: that is the divergence.
    (tmp_path / "bare.trace").write_text("".join(
        line for line in text.splitlines(keepends=True) if " axis 0 start=" not in line))
    bare = l6470emu.replay(tmp_path / "bare.trace")
    assert not bare.matched
    assert "SW (driven by its axis) expected low" in bare.divergences[0].summary


def test_an_axis_a_board_attaches_while_recording_is_in_its_trace(tmp_path):
    board = l6470emu.Board("L6470", trace_path=tmp_path / "board.trace")
    board.attach_axis(0, "start=500,switch=home@0")
    spi = board.spidev(0, 0)
    spi.mode = 3
    for byte in (0x40, 0x00, 0x02, 0x00):  # Move 512 reverse: onto the switch
        spi.xfer2([byte])
    board.advance(1.0)
    board.close()
    text = (tmp_path / "board.trace").read_text()
    assert " axis 0 start=500,switch=home@0:below:no\n" in text, text
    assert l6470emu.replay(tmp_path / "board.trace").matched
