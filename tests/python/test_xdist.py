"""`pytest -n 2` (pytest-xdist, Debian's python3-pytest-xdist) runs fixture-using tests in two
worker processes at once without collisions: every board, trace and log is the test's own."""
import os
import subprocess
import sys
import textwrap

import pytest

TESTS = textwrap.dedent('''
    import sys
    import pytest

    def body(spi, n):
        spi.mode = 3
        for byte in (0x40 | 1, 0x00, n >> 8, n & 0xFF):
            spi.xfer2([byte])

    @pytest.mark.parametrize("n", range(1, 7))
    def test_in_process(l6470_board, n):
        body(l6470_board.spidev(0, 0), n * 100)
        busy = l6470_board.line(0, "BUSY")
        busy.request("t", 6)
        assert busy.wait_edge(5.0) is not None
        assert f"Move(FWD, {n * 100} microsteps)" in l6470_board.decode()

    @pytest.mark.parametrize("n", range(1, 5))
    def test_under_the_preload(spidev_board, tmp_path, n):
        script = tmp_path / "d.py"
        script.write_text("import spidev\\nspi = spidev.SpiDev()\\nspi.open(0, 0)\\nspi.mode = 3\\n"
                          f"for b in (0x41, 0, {n}, 0): spi.xfer2([b])\\n")
        spidev_board.python(script)
        assert f"Move(FWD, {n * 256} microsteps)" in spidev_board.decode()

    @pytest.mark.parametrize("n", range(1, 5))
    def test_chain(l6470_chain, n):
        l6470_chain.move(0, True, n * 10)
        assert l6470_chain.get_status(0) is not None
''')


def test_two_workers_run_every_fixture_at_once_without_collisions(tmp_path):
    pytest.importorskip("xdist", reason="pytest-xdist is not installed (Debian: python3-pytest-xdist)")
    pytest.importorskip("spidev")
    (tmp_path / "test_parallel.py").write_text(TESTS)
    env = dict(os.environ, PYTEST_DISABLE_PLUGIN_AUTOLOAD="1")
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "xdist", "-p", "l6470emu.pytest_plugin", "-p", "no:cacheprovider",
         "-n", "2", "-v", str(tmp_path / "test_parallel.py")],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "14 passed" in result.stdout
    assert "[gw0]" in result.stdout and "[gw1]" in result.stdout  # both workers ran tests
