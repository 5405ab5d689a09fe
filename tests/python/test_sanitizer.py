"""The driver sanitizer from Python: l6470emu.Chain and both pytest fixtures default to
check="error" (the first broken rule of the chip raises SanitizerError with its report, or ends
a program under the preload with SANITIZER_EXIT_STATUS); "warn" gives SanitizerWarning, "off"
nothing; check_allow= lets named rules pass."""
import sys

import pytest

import l6470emu

# A py-spidev driver that forgets `spi.mode = 3` (spidev's default is mode 0): it reads CONFIG
# after a NOP, one CS frame per byte, as a single-chip driver does.
MODE0_DRIVER = """
import spidev
spi = spidev.SpiDev()
spi.open(0, 0)
spi.max_speed_hz = 1000000
spi.xfer2([0x00])
config = [spi.xfer2([b])[0] for b in (0x38, 0x00, 0x00)]
print("CONFIG=0x%02X%02X" % (config[1], config[2]))
"""


def test_a_chain_raises_the_report_of_the_first_broken_rule_by_default():
    chain = l6470emu.Chain(["L6470", "L6470"])
    assert chain.check == "error" and chain.check_allow == []
    with pytest.raises(l6470emu.SanitizerError) as raised:
        chain.frame(b"\xD0")  # one byte for a chain of two
    report = str(raised.value)
    assert "driver sanitizer: FRAME_LENGTH on Chain, every chip, frame 1" in report
    assert "datasheet: §8 Serial interface and Figure 18" in report
    assert "check.allow=FRAME_LENGTH" in report
    # An exception the test may catch: nothing "ends here".
    assert "SanitizerError is raised here" in report and "the run ends here" not in report


def test_a_refused_command_names_the_chip_the_frame_and_the_byte():
    chain = l6470emu.Chain(2)
    chain.move(1, True, 100000)
    with pytest.raises(l6470emu.SanitizerError, match=r"NOTPERF_CMD on Chain, chip 1, frame \d+, byte 1"):
        chain.move(1, True, 100)  # Move while the motor runs


def test_warn_gives_a_warning_per_broken_rule_and_off_nothing(recwarn):
    chain = l6470emu.Chain(check="warn")
    with pytest.warns(l6470emu.SanitizerWarning, match="Chain: chip 0: WRONG_CMD: byte 0xE5: no such command"):
        chain.frame(b"\xE5")
    chain.check = "off"
    chain.frame(b"\xE5")
    assert not [w for w in recwarn if issubclass(w.category, l6470emu.SanitizerWarning)]


def test_an_allowed_rule_passes_and_the_others_still_count():
    chain = l6470emu.Chain(check_allow=["WRONG_CMD"])
    chain.frame(b"\xE5")
    assert chain.get_status(0).WRONG_CMD  # the chip still did what it does
    with pytest.raises(l6470emu.SanitizerError, match="UNUSED_BITS"):
        chain.set_param(0, "MAX_SPEED", 0x0400)  # MAX_SPEED has 10 bits


def test_an_answer_replaced_before_it_was_read_is_a_broken_rule():
    chain = l6470emu.Chain()
    chain.send(0, b"\x21\x00")  # GetParam(ABS_POS): 3 answer bytes, one read
    with pytest.raises(l6470emu.SanitizerError, match="ANSWER_LOST on Chain, chip 0"):
        chain.get_status(0)


def test_bad_check_settings_are_refused_with_a_suggestion():
    with pytest.raises(ValueError, match=r"check must be off, warn or error, not 'eror' \(did you mean error\?\)"):
        l6470emu.Chain(check="eror")
    with pytest.raises(ValueError, match=r"names no rule 'SPI_MOD' \(did you mean SPI_MODE\?"):
        l6470emu.Chain(check_allow=["SPI_MOD"])
    with pytest.raises(TypeError, match="a list of rule names"):
        l6470emu.Chain(check_allow="SPI_MODE")


def test_the_rules_carry_their_names_and_datasheet_places():
    rules = {name: (about, where) for name, about, where in l6470emu.check_rules()}
    assert "SPI_MODE" in rules and "§8" in rules["SPI_MODE"][1]
    assert rules["SCK_SPEED"][1].startswith("Table 5")
    assert l6470emu.SANITIZER_EXIT_STATUS == 86


def test_the_fixture_chain_fails_the_test_on_a_broken_rule(l6470_chain):
    with pytest.raises(l6470emu.SanitizerError, match="WRONG_CMD"):
        l6470_chain.frame(b"\xEB")


@pytest.mark.l6470_chain("L6470", check="warn")
def test_the_marker_sets_the_fixtures_check(l6470_chain, spidev_board):
    assert l6470_chain.check == "warn"
    assert "check=warn" in spidev_board.description


def test_a_mode0_py_spidev_driver_reads_config_as_0x2E08_and_is_stopped_with_the_report(spidev_board, tmp_path):
    script = tmp_path / "mode0.py"
    script.write_text(MODE0_DRIVER)
    spidev_board.check = "warn"
    assert spidev_board.python(script).stdout.split() == ["CONFIG=0x2E08"]  # silicon reads 0x2E08 too
    assert "SPI_MODE: the host clocks in SPI mode 0" in spidev_board.log()
    spidev_board.check = "error"
    result = spidev_board.python(script, check=False)
    assert result.returncode == l6470emu.SANITIZER_EXIT_STATUS and "CONFIG" not in result.stdout
    assert "l6470emu: driver sanitizer: SPI_MODE on spidev0.0, chip 0, frame 1, byte 0" in result.stderr
    assert "SPI mode 0 (CPOL=0, CPHA=0)" in result.stderr
    assert "datasheet: §8 Serial interface" in result.stderr
    with pytest.raises(pytest.fail.Exception, match="broke a rule of the chip") as failed:
        spidev_board.python(script)
    assert "SPI_MODE on spidev0.0" in str(failed.value)
    spidev_board.check_allow = ["SPI_MODE"]
    assert spidev_board.python(script).stdout.split() == ["CONFIG=0x2E08"]
