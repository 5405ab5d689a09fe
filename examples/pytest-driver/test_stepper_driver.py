# Tests an unmodified py-spidev driver (stepper_driver.py) against two emulated L6470s.
import sys
from pathlib import Path

import pytest

DRIVER = Path(__file__).with_name("stepper_driver.py")


@pytest.mark.l6470_chain("2xL6470")
def test_a_move_ends_on_target_and_leaves_the_other_chip_alone(spidev_board):
    result = spidev_board.run([sys.executable, DRIVER, "--chips", "2", "--chip", "1", "--move", "-3200"])
    assert result.stdout == "chip 1 at -3200\n"
    log = spidev_board.decode()          # every command the driver sent, per chip
    assert "chip 1   Move(REV, 3200 microsteps)" in log
    assert "chip 0   Move" not in log
    assert spidev_board.replay().matched  # the recording replays byte-exact


@pytest.mark.l6470_chain("2xL6470")
def test_the_driver_class_in_the_test_process(l6470_board, monkeypatch):
    # The driver's own spidev.SpiDev becomes the board's; its time.sleep/monotonic are the board's
    # (the fixture's patch_time), so wait_idle's polling takes virtual time only.
    import stepper_driver
    monkeypatch.setattr(stepper_driver.spidev, "SpiDev", l6470_board.SpiDev)
    chain = stepper_driver.StepperChain(2)
    chain.status(1)
    chain.move(1, 6400)
    chain.wait_idle(1)
    assert chain.position(1) == 6400 and chain.position(0) == 0
    assert l6470_board.seconds > 0.1           # the move took virtual time
    assert "chip 1   Move(FWD, 6400 microsteps)" in l6470_board.decode()
