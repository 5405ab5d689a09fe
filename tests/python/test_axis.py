"""The axis from Python: Chain and Board (and so the l6470_chain and l6470_board fixtures) attach
an axis, read its true position, change its load and place switches."""
import pytest

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
