"""l6470emu.Board and the l6470_board fixture: a driver class tested in the test process, with a
spidev.SpiDev work-alike and libgpiod-like lines in virtual time. The same driver code run under
the preload with the real py-spidev (spidev_board) records the very same trace."""
import errno
import sys
import textwrap
import time

import pytest

import l6470emu
from l6470emu.board import (LINE_REQ_DIR_IN, LINE_REQ_DIR_OUT, LINE_REQ_EV_BOTH_EDGES, LINE_REQ_EV_RISING_EDGE,
                            LINE_REQ_FLAG_ACTIVE_LOW, LineEvent)

# One driver body, run in process (spi = board.spidev) and under the preload (spi = spidev.SpiDev).
DRIVER_BODY = textwrap.dedent("""
    spi.mode = 3
    spi.max_speed_hz = 1000000
    out = [spi.xfer([0xD0, 0, 0]), spi.xfer2([0xD0, 0, 0]), list(spi.xfer3([0xD0, 0, 0])), spi.readbytes(2)]
    spi.writebytes([0, 0])
    spi.writebytes2(bytes([0, 0]))
    for b in (0x50, 0x00, 0x10, 0x00):      # Run forward
        out.append(spi.xfer2([b]))
    spi.xfer2([0x20, 0x00, 0x00, 0x00], 250000, 5)   # GetParam ABS_POS at 250 kHz, 5 us delay
    spi.xfer([0xB0])                        # SoftStop
    out.append(spi.bits_per_word)
    spi.close()
    """)


def run_in_process(board):
    spi = board.spidev(0, 0)
    scope = {"spi": spi}
    exec(DRIVER_BODY, scope)
    return scope["out"]


def frames_of(trace_text):
    return [line for line in trace_text.splitlines() if not line.startswith(("l6470emu-trace", "chain", "#"))]


@pytest.mark.l6470_chain(check="warn")  # the body sends frames of several bytes on purpose
def test_a_driver_body_records_the_same_trace_in_process_as_under_the_preload_with_py_spidev(spidev_board, tmp_path):
    pytest.importorskip("spidev")
    script = tmp_path / "driver.py"
    script.write_text("import spidev\nspi = spidev.SpiDev()\nspi.open(0, 0)\n" + DRIVER_BODY + "print(out)\n")
    result = spidev_board.python(script)
    board = l6470emu.Board("L6470", options="check=warn", trace_path=tmp_path / "inproc.trace")
    out = run_in_process(board)
    board.close()
    assert result.stdout == f"{out}\n"
    assert frames_of((tmp_path / "inproc.trace").read_text()) == frames_of(spidev_board.trace_path.read_text())


def test_spidev_attributes_behave_as_py_spidev_before_open_after_open_and_after_close():
    board = l6470emu.Board("L6470", options="speed=2000000")
    spi = board.SpiDev()
    assert (spi.mode, spi.max_speed_hz, spi.bits_per_word, spi.lsbfirst) == (0, 0, 0, False)
    with pytest.raises(OSError) as e:
        spi.mode = 3
    assert e.value.errno == errno.EBADF
    with pytest.raises(OSError):
        spi.xfer([0])
    spi.open(0, 0)
    assert (spi.mode, spi.max_speed_hz, spi.bits_per_word) == (0, 2000000, 8)
    spi.mode = 3
    spi.lsbfirst = True
    assert (spi.mode, spi.lsbfirst, spi.cshigh) == (3, True, False)
    with pytest.raises(TypeError):
        spi.mode = 4
    with pytest.raises(OSError) as e:
        spi.threewire = True  # the emulated controller cannot do 3-wire: spi_setup's EINVAL
    assert e.value.errno == errno.EINVAL
    spi.close()
    assert spi.mode == 0
    with pytest.raises(FileNotFoundError):
        spi.open(1, 0)


def test_the_mode_is_kept_in_the_device_and_shared_by_every_open_file_as_in_the_kernel():
    board = l6470emu.Board("L6470", check="warn")
    a, b = board.spidev(0, 0), board.spidev(0, 0)
    a.mode = 1
    b.close()
    b.open(0, 0)
    assert b.mode == 1  # a second open reads the device's mode
    a.xfer2([0x00])
    assert "SPI_MODE: the host clocks in SPI mode 1" in board.log()  # handed to the board, which says so


def test_a_board_checks_at_error_unless_told_otherwise():
    board = l6470emu.Board("L6470")
    spi = board.spidev(0, 0)  # mode 0, spidev's default
    with pytest.raises(l6470emu.SanitizerError) as e:
        spi.xfer2([0x00])
    assert "SPI mode 0 (CPOL=0, CPHA=0)" in str(e.value)
    # check= of the description, or check_allow=, let it pass.
    for quiet in (l6470emu.Board("L6470", options="check=warn"), l6470emu.Board("L6470", check_allow=["SPI_MODE"])):
        assert quiet.spidev(0, 0).xfer2([0x00]) == [0x00]


def test_spidev_is_a_context_manager_and_ends_closed():
    board = l6470emu.Board("L6470")
    with board.spidev(0, 0) as spi:
        spi.mode = 3
        assert spi.xfer2([0x00]) == [0x00]
    with pytest.raises(OSError):
        spi.xfer2([0x00])


def test_a_message_takes_its_bus_time_and_nothing_else_moves_time():
    board = l6470emu.Board("L6470", options="speed=1000000", check="warn")  # 3 bytes in one frame on purpose
    spi = board.spidev(0, 0)
    spi.mode = 3
    t0 = board.tick
    spi.xfer2([0, 0, 0])          # 3 bytes at 1 MHz: 24 us, then 10 us CS high: 136 ticks
    assert board.tick - t0 == 136
    board.level(0, "BUSY")
    assert board.tick - t0 == 136  # reading a pin takes no time
    board.advance(0.001)
    assert board.tick - t0 == 136 + 4000


def run_forward(spi, speed=0x1000):
    for byte in (0x51, speed >> 16 & 0xF, speed >> 8 & 0xFF, speed & 0xFF):
        spi.xfer2([byte])


def test_waiting_on_busy_runs_virtual_time_exactly_to_its_edge():
    board = l6470emu.Board("L6470")
    spi = board.spidev(0, 0)
    spi.mode = 3
    busy = board.gpiochip(0).find_line("BUSY")
    busy.request(consumer="test", type=LINE_REQ_EV_BOTH_EDGES)
    spi.xfer2([0xD0]); spi.xfer2([0]); spi.xfer2([0])  # GetStatus (clears UVLO)
    for byte in (0x40 | 1, 0x00, 0x00, 0xC8):          # Move 200 microsteps forward
        spi.xfer2([byte])
    falling = busy.wait_edge(1.0)
    assert falling.type == LineEvent.FALLING_EDGE and busy.get_value() == 0
    wall = time.perf_counter()
    rising = busy.wait_edge(10.0)
    assert rising.type == LineEvent.RISING_EDGE
    assert board.tick == rising.tick > falling.tick  # time stopped at the edge, not the timeout
    assert busy.get_value() == 1
    assert rising.sec * 10**9 + rising.nsec == board.monotonic_ns()
    assert time.perf_counter() - wall < 5  # seconds of motion, not of waiting (loose; never timed)


def test_a_wait_without_an_edge_ends_at_its_timeout_and_says_so():
    board = l6470emu.Board("L6470")
    flag = board.line(0, "FLAG")
    flag.request("test", LINE_REQ_EV_BOTH_EDGES)
    t0 = board.tick
    assert flag.event_wait(sec=0, nsec=500_000) is False
    assert board.tick - t0 == 2000  # 500 us
    assert flag.wait_edge(0.25) is None


def test_rising_only_requests_active_low_and_outputs_follow_libgpiod():
    board = l6470emu.Board("2xL6470")
    chip = board.gpiochip("gpiochip0")
    assert chip.num_lines() == 10 and chip.find_line("BUSY1").offset() == 5
    busy = chip.find_line("BUSY0")
    busy.request("t", LINE_REQ_EV_RISING_EDGE, flags=LINE_REQ_FLAG_ACTIVE_LOW)
    assert busy.get_value() == 0  # not busy: high, read active-low
    with pytest.raises(OSError) as e:
        busy.request("again", LINE_REQ_DIR_IN)
    assert e.value.errno == errno.EBUSY
    sw = chip.find_line("SW1")
    sw.request("t", LINE_REQ_DIR_OUT, default_val=1)
    sw.set_value(0)
    assert board.level(1, "SW") == 0
    spi = board.spidev(0, 0)
    spi.mode = 3
    for byte in (0x41, 0x00, 0x00, 0xC8):  # Move on chip 0, NOP to chip 1
        spi.xfer2([byte, 0x00])
    event = busy.wait_edge(1.0)  # BUSY falls: active-low makes it a rising edge
    assert event.type == LineEvent.RISING_EDGE and busy.get_value() == 1
    assert busy.wait_edge(1.0) is None  # the end of the move is a (filtered) falling edge


def test_a_bulk_wait_returns_the_lines_with_events():
    board = l6470emu.Board("L6470")
    lines = board.gpiochip(0).get_lines([0, 1])  # BUSY, FLAG
    lines.request("t", LINE_REQ_EV_BOTH_EDGES)
    spi = board.spidev(0, 0)
    spi.mode = 3
    run_forward(spi)
    ready = lines.event_wait(sec=1)
    assert [line.name() for line in ready] == ["BUSY"]
    assert lines.event_wait() is not None  # waiting reads nothing: the event is still there
    ready.to_list()[0].event_read()
    assert lines.event_wait(nsec=1000) is None


@pytest.mark.l6470_chain("2xL6470")
@pytest.mark.l6470_board(options="speed=4000000")
def test_the_fixture_takes_the_chips_and_options_and_puts_time_on_the_board(l6470_board):
    assert l6470_board.chips() == ["L6470", "L6470"]
    t0 = l6470_board.tick
    time.sleep(0.5)  # the code under test sleeps in virtual time
    assert l6470_board.tick - t0 == 2_000_000
    assert time.monotonic() == l6470_board.monotonic()
    with l6470_board.spidev(0, 0) as spi:
        assert spi.max_speed_hz == 4_000_000


@pytest.mark.l6470_board(patch_time=False, record=False)
def test_the_fixture_can_leave_time_alone(l6470_board):
    t0 = l6470_board.tick
    time.sleep(0.001)
    assert l6470_board.tick == t0
    with pytest.raises(RuntimeError):
        l6470_board.trace()


def test_the_fixture_records_a_trace_that_decodes_and_replays(l6470_board):
    spi = l6470_board.spidev(0, 0)
    spi.mode = 3
    run_forward(spi)
    assert "Run(FWD" in l6470_board.decode()
    assert l6470_board.replay().matched


@pytest.mark.l6470_board(colour="red")
def test_an_unknown_fixture_option_is_named(request):
    with pytest.raises(pytest.UsageError, match="colour"):
        request.getfixturevalue("l6470_board")


def test_a_board_with_two_chains_opens_each_spidev_and_gpiochip():
    board = l6470emu.Board(description="chips=L6470 bus=0 cs=0 gpiochip=0; chips=L6480 bus=1 cs=2 gpiochip=3 mode=3")
    spi = board.spidev(1, 2)
    spi.mode = 3
    assert spi.xfer2([0x00]) == [0x00]
    assert board.gpiochip("/dev/gpiochip3").find_line("BUSY") is not None
    with pytest.raises(FileNotFoundError):
        board.gpiochip(7)
    with pytest.raises(ValueError, match="virtual time"):
        l6470emu.Board("L6470", options="time=wall")


def test_the_python_guide_documents_every_option_of_the_fixtures():
    from pathlib import Path
    from l6470emu import pytest_plugin
    guide = (Path(__file__).resolve().parents[2] / "docs" / "guide" / "python.md").read_text()
    section = guide[guide.index("## Testing your driver with pytest"):guide.index("## Examples\n")]
    for option in pytest_plugin._BOARD_OPTIONS:
        assert f"`{option}`" in section, option
    board = pytest_plugin.SpidevBoard(["L6470"], Path("/tmp"))
    for attribute in (a for a in vars(board) if not a.startswith("_")):
        assert f"`{attribute}`" in section, attribute


def test_a_board_at_check_warn_gives_a_sanitizer_warning_as_a_chain_does():
    board = l6470emu.Board("L6470", check="warn")
    spi = board.spidev(0, 0)  # mode 0, spidev's default
    with pytest.warns(l6470emu.SanitizerWarning, match="SPI_MODE: the host clocks in SPI mode 0"):
        spi.xfer2([0x00])
    assert "SPI_MODE: the host clocks in SPI mode 0" in board.log()  # and the log keeps it


@pytest.mark.l6470_chain("L6470", check="warn")
def test_the_board_fixture_at_check_warn_gives_a_sanitizer_warning(l6470_board):
    spi = l6470_board.spidev(0, 0)
    with pytest.warns(l6470emu.SanitizerWarning, match="SPI_MODE"):
        spi.xfer2([0x00])
