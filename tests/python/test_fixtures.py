"""The pytest plugin's fixtures: l6470_chain from the marker's chips, and spidev_board
running a program under the preload library with a chain and a recorded trace."""
import sys

import pytest

import l6470emu

SPIDEV_SCRIPT = """
import spidev
spi = spidev.SpiDev()
spi.open({bus}, {cs})
spi.mode = 3
spi.max_speed_hz = 1000000
n = {chips}
spi.xfer2([0xD0] * n)
print(" ".join("%02X%02X" % (a, b) for a, b in zip(spi.xfer2([0] * n), spi.xfer2([0] * n))))
"""


def test_l6470_chain_is_one_l6470_by_default(l6470_chain):
    assert l6470_chain.variants == ["L6470"] and l6470_chain.get_status(0) == 0x7C03


@pytest.mark.l6470_chain("L6470", "2xL6480")
def test_l6470_chain_takes_its_chips_from_the_marker(l6470_chain):
    assert l6470_chain.variants == ["L6470", "L6480", "L6480"]


@pytest.mark.l6470_chain("L6470", "2xL6480")
def test_spidev_board_runs_a_program_against_the_markers_chips(spidev_board, tmp_path):
    script = tmp_path / "status.py"
    script.write_text(SPIDEV_SCRIPT.format(bus=0, cs=0, chips=3))
    assert spidev_board.description == "bus=0 cs=0 chips=L6470,2xL6480 time=virtual check=error"
    result = spidev_board.python(script)
    assert result.stdout.split() == ["7C03", "E403", "E403"]
    assert spidev_board.trace().chain == "L6470,2*L6480"
    assert spidev_board.replay().matched
    assert "chip 2   GetStatus" in spidev_board.decode()


def test_spidev_board_settings_reach_the_board(spidev_board, tmp_path):
    script = tmp_path / "status.py"
    script.write_text(SPIDEV_SCRIPT.format(bus=2, cs=1, chips=1))
    spidev_board.bus, spidev_board.cs, spidev_board.time = 2, 1, "wall"
    spidev_board.options = "speed=2000000"
    assert spidev_board.device == "/dev/spidev2.1"
    assert spidev_board.python(script).stdout.split() == ["7C03"]
    spidev_board.trace_path = None
    assert "L6470EMU_TRACE" not in spidev_board.env()
    spidev_board.python(script)
    with pytest.raises(RuntimeError, match="no trace recorded"):
        spidev_board.trace()


def test_spidev_board_fails_the_test_with_the_programs_output(spidev_board, tmp_path):
    script = tmp_path / "fails.py"
    script.write_text("import sys\nprint('to stdout')\nsys.exit('to stderr')\n")
    with pytest.raises(pytest.fail.Exception) as failed:
        spidev_board.python(script)
    assert "exited with 1" in str(failed.value) and "to stdout" in str(failed.value) and "to stderr" in str(failed.value)
    assert spidev_board.python(script, check=False).returncode == 1


def test_the_preload_library_is_found_and_can_be_overridden(monkeypatch, tmp_path):
    path = l6470emu.preload_library()
    assert path.endswith("libl6470emu-preload.so")
    monkeypatch.setenv("L6470EMU_PRELOAD", str(tmp_path / "nothing.so"))
    with pytest.raises(RuntimeError, match="no such file"):
        l6470emu.preload_library()
    assert l6470emu.program().endswith("l6470emu")
