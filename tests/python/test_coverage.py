"""Interface coverage from Python (docs/coverage-python.md): a Board or Chain given coverage=FILE
(or run with $L6470EMU_COVERAGE set) merges exactly what it met into FILE when closed, destroyed
or at the interpreter's exit; the pytest plugin's --l6470emu-coverage collects a whole session,
pytest-xdist workers and programs under the preload included, into one file."""
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import l6470emu
from l6470emu import Board, Chain
from l6470emu.board import LINE_REQ_DIR_IN, LINE_REQ_EV_BOTH_EDGES, LineEvent

ENV = "L6470EMU_COVERAGE"
CATEGORIES = ("commands", "registers read", "registers written", "refusals", "flags raised", "flags observed",
              "events", "step modes", "chain positions", "pin edges", "rules broken")


@pytest.fixture(autouse=True)
def no_session_coverage(monkeypatch):
    """These tests name their own files: a suite run with $L6470EMU_COVERAGE set decides nothing here."""
    monkeypatch.delenv(ENV, raising=False)


def hits(path, variant="L6470"):
    """The points of `variant` hit in the coverage file, by category (every category present)."""
    data = json.loads(Path(path).read_text())
    assert data["format"] == "l6470emu-coverage"
    hit = data["variants"][variant]["hit"]
    assert set(hit) <= set(CATEGORIES)
    return {c: set(hit.get(c, ())) for c in CATEGORIES}


def python_env():
    """The environment of a child Python: this one's, without a coverage file of the suite's own."""
    env = dict(os.environ, PYTEST_DISABLE_PLUGIN_AUTOLOAD="1")
    env.pop(ENV, None)
    return env


def drive_the_chain_subset(chain):
    """SetParam(ACC), Move FWD, GetStatus, GoUntil ACT=1 FWD, a refused WS write while moving, and
    an overcurrent raised with STATUS never read after it."""
    chain.get_status(0)                  # GetStatus: clears the power-up UVLO
    chain.set_param(0, "ACC", 0x20)      # accepted: the motor is stopped
    chain.move(0, True, 20000)
    chain.advance(seconds=0.01)
    chain.set_param(0, "ACC", 0x40)      # refused: ACC is WS and the motor runs (NOTPERF_CMD)
    chain.advance(seconds=5)             # the move ends
    chain.go_until(0, True, True, 0x4000)
    chain.set_overcurrent(0, True)       # OCD raised; nobody reads STATUS after it


def test_a_chain_merges_exactly_the_points_it_met_into_its_file_when_closed(tmp_path):
    path = tmp_path / "chain.coverage"
    chain = Chain("L6470", check="warn", coverage=path)
    assert chain.coverage_path == str(path)
    with pytest.warns(l6470emu.SanitizerWarning, match="NOTPERF_CMD"):
        drive_the_chain_subset(chain)
    assert not path.exists()  # nothing is written before the chain is closed
    chain.close()
    hit = hits(path)
    assert hit["commands"] == {"GetStatus", "Move FWD", "GoUntil FWD", "GoUntil ACT=1"}
    assert hit["registers written"] == {"ACC"}
    assert hit["registers read"] == set()
    assert hit["refusals"] == {"SetParam(ACC)"}
    assert hit["events"] == {"OCD"}
    assert hit["step modes"] == {"1/128"}
    assert hit["chain positions"] == {"chip 0 of 1"}
    assert hit["pin edges"] == set()
    assert hit["rules broken"] == {"NOTPERF_CMD"}
    # Raised: seen in the chip after each call; observed: read by the host (only the first GetStatus).
    assert hit["flags raised"] == {"HiZ", "UVLO", "BUSY", "DIR", "MOT_STATUS acceleration", "NOTPERF_CMD", "OCD"}
    assert hit["flags observed"] == {"HiZ", "UVLO"}
    assert "OCD" in hit["flags raised"] and "OCD" not in hit["flags observed"]
    assert json.loads(path.read_text()) == chain.coverage_data()


def test_a_board_merges_the_driver_s_commands_pin_reads_and_edge_events(tmp_path):
    path = tmp_path / "board.coverage"
    with Board("L6470", coverage=path) as board:
        flag = board.line(0, "FLAG")
        flag.request("driver", LINE_REQ_DIR_IN)
        assert board.level(0, "FLAG") == 0  # the test's own look: nothing observed
        assert "flags observed" not in board.coverage_data()["variants"]["L6470"]["hit"]
        assert flag.get_value() == 0        # the driver reads FLAG low: the power-up UVLO observed
        busy = board.line(0, "BUSY")
        busy.request("driver", LINE_REQ_EV_BOTH_EDGES)
        spi = board.spidev(0, 0)
        spi.mode = 3
        for byte in (0x41, 0x00, 0x10, 0x00):  # Move FWD 4096 microsteps
            spi.xfer2([byte])
        assert busy.event_read().type == LineEvent.FALLING_EDGE
        assert busy.event_read().type == LineEvent.RISING_EDGE
    hit = hits(path)
    assert hit["commands"] == {"Move FWD"}
    assert hit["flags observed"] == {"UVLO"}
    assert hit["pin edges"] == {"BUSY falling", "BUSY rising"}
    assert hit["step modes"] == {"1/128"}
    assert hit["registers written"] == hit["refusals"] == hit["events"] == set()


def test_two_disjoint_runs_merged_give_the_union(tmp_path):
    one, other, both = tmp_path / "one.coverage", tmp_path / "other.coverage", tmp_path / "both.coverage"
    for files, run in (((one, both), lambda c: c.move(0, True, 100)), ((other, both), lambda c: c.run(0, False, 1000))):
        for path in files:
            with Chain("L6470", coverage=path) as chain:
                run(chain)
    assert hits(one)["commands"] == {"Move FWD"}
    assert hits(other)["commands"] == {"Run REV"}
    assert hits(both)["commands"] == {"Move FWD", "Run REV"}
    assert hits(both)["step modes"] == {"1/128"}
    # The report of the two files is the report of their merge.
    assert l6470emu.coverage_report([one, other]) == l6470emu.coverage_report(both)
    assert l6470emu.coverage_total([one, other]) == l6470emu.coverage_total(both)
    hit, total = l6470emu.coverage_total(both)
    assert 0 < hit < total
    assert "Run REV" in l6470emu.coverage_report(one, show_missing=True)  # never met in `one`
    assert json.loads(l6470emu.coverage_report(both, format="json"))


def test_l6470emu_coverage_is_the_default_file_and_false_turns_collection_off(tmp_path, monkeypatch):
    path = tmp_path / "env.coverage"
    monkeypatch.setenv(ENV, str(path))
    Chain("L6470", coverage=False).move(0, True, 100)
    off = Board("L6470", coverage=False)
    assert off.coverage_data() is None and off.coverage_path is None
    del off
    assert not path.exists()
    chain = Chain("L6470")
    assert chain.coverage_path == str(path)
    chain.move(0, False, 100)
    del chain  # destroyed, never closed: merged all the same
    board = Board("L6470")
    board.fault(0, "OCD")
    board.close()
    hit = hits(path)
    assert hit["commands"] == {"Move REV"}
    assert hit["events"] == {"OCD"}


def test_coverage_true_collects_in_memory_only(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    chain = Chain("L6470", coverage=True)
    chain.hard_hiz(0)
    assert chain.coverage_path is None
    assert chain.coverage_data()["variants"]["L6470"]["hit"]["commands"] == ["HardHiZ"]
    chain.close()
    assert Chain("L6470").coverage_data() is None
    assert list(tmp_path.iterdir()) == []


def test_a_file_that_cannot_take_coverage_is_refused_at_construction_in_one_line(tmp_path, monkeypatch):
    nowhere = tmp_path / "missing" / "x.coverage"
    not_coverage = tmp_path / "notes.txt"
    not_coverage.write_text("hello\n")
    for make in (lambda p: Chain("L6470", coverage=p), lambda p: Board("L6470", coverage=p)):
        for bad, why in ((nowhere, "cannot write in"), (not_coverage, "not a coverage file"), (tmp_path, "a directory")):
            with pytest.raises(ValueError, match=why) as refused:
                make(bad)
            assert str(refused.value).startswith(f"coverage: {bad}") and "\n" not in str(refused.value)
        monkeypatch.setenv(ENV, str(nowhere))
        with pytest.raises(ValueError, match=f"^{ENV}: {nowhere}: cannot write in"):
            make(None)
        monkeypatch.delenv(ENV)
    assert not_coverage.read_text() == "hello\n"


def test_a_relative_file_is_the_one_of_the_directory_at_construction(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    chain = Chain("L6470", coverage="rel.coverage")
    (tmp_path / "elsewhere").mkdir()
    monkeypatch.chdir(tmp_path / "elsewhere")
    chain.go_home(0)
    chain.close()
    assert hits(tmp_path / "rel.coverage")["commands"] == {"GoHome"}


def test_objects_never_closed_give_their_coverage_at_the_interpreter_s_exit(tmp_path):
    path = tmp_path / "exit.coverage"
    script = textwrap.dedent(f"""
        import l6470emu
        chain = l6470emu.Chain("L6470", coverage={str(path)!r})
        chain.go_mark(0)
        board = l6470emu.Board("L6470", coverage={str(path)!r})
        board.fault(0, "STALL_A")
        kept = [chain, board]
        kept.append(kept)  # a cycle: nothing is destroyed before the exit handlers run
    """)
    subprocess.run([sys.executable, "-c", script], env=python_env(), check=True, timeout=60)
    hit = hits(path)
    assert hit["commands"] == {"GoMark"}
    assert hit["events"] == {"STALL_A"}


def test_reports_of_unreadable_files_or_in_unknown_formats_are_value_errors(tmp_path):
    with pytest.raises(ValueError, match="missing.coverage"):
        l6470emu.coverage_report(tmp_path / "missing.coverage")
    (tmp_path / "bad.coverage").write_text("{}")
    with pytest.raises(ValueError, match="bad.coverage"):
        l6470emu.coverage_total([tmp_path / "bad.coverage"])
    with pytest.raises(ValueError, match="no coverage file named"):
        l6470emu.coverage_report([])
    Chain("L6470", coverage=tmp_path / "good.coverage").close()
    with pytest.raises(ValueError, match="format lcov"):
        l6470emu.coverage_report(tmp_path / "good.coverage", format="lcov")


# ---- the pytest plugin --------------------------------------------------------------------------

TWO_TESTS = textwrap.dedent('''
    def test_a_move(l6470_chain):
        l6470_chain.move(0, True, 100)

    def test_a_run_on_a_board(l6470_board):
        spi = l6470_board.spidev(0, 0)
        spi.mode = 3
        for byte in (0x50, 0x00, 0x10, 0x00):  # Run REV
            spi.xfer2([byte])
''')


def run_pytest(tmp_path, *args):
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "l6470emu.pytest_plugin", "-p", "no:cacheprovider", *args],
        cwd=tmp_path, env=python_env(), capture_output=True, text=True, timeout=120)


def test_the_plugin_s_xdist_workers_merge_into_one_file_and_the_controller_sums_it_up(tmp_path):
    pytest.importorskip("xdist", reason="pytest-xdist is not installed (Debian: python3-pytest-xdist)")
    (tmp_path / "test_two.py").write_text(TWO_TESTS)
    result = run_pytest(tmp_path, "-p", "xdist", "-n", "2", "-v", "--l6470emu-coverage=session.coverage", "test_two.py")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "[gw0]" in result.stdout and "[gw1]" in result.stdout  # one test on each worker
    path = tmp_path / "session.coverage"
    hit = hits(path)
    assert hit["commands"] == {"Move FWD", "Run REV"}
    met, total = l6470emu.coverage_total(path)
    assert f"{met}/{total} interface points met ({100 * met / total:.1f}%), merged into {path}" in result.stdout


def test_the_plugin_gives_programs_it_runs_the_coverage_file(tmp_path):
    pytest.importorskip("spidev")
    (tmp_path / "test_program.py").write_text(textwrap.dedent('''
        def test_a_program(spidev_board, tmp_path):
            script = tmp_path / "driver.py"
            script.write_text("import spidev\\nspi = spidev.SpiDev()\\nspi.open(0, 0)\\nspi.mode = 3\\nspi.xfer2([0x70])\\n")
            spidev_board.python(script)  # GoHome, under the preload
    '''))
    result = run_pytest(tmp_path, "-q", "--l6470emu-coverage=session.coverage", "test_program.py")
    assert result.returncode == 0, result.stdout + result.stderr
    assert hits(tmp_path / "session.coverage")["commands"] == {"GoHome"}


def test_an_unwritable_coverage_file_is_a_usage_error_at_start_up(tmp_path):
    (tmp_path / "test_two.py").write_text(TWO_TESTS)
    result = run_pytest(tmp_path, "-q", f"--l6470emu-coverage={tmp_path}/missing/session.coverage", "test_two.py")
    assert result.returncode == 4, result.stdout + result.stderr
    assert f"--l6470emu-coverage: {tmp_path}/missing/session.coverage: cannot write in" in result.stderr
    assert "passed" not in result.stdout  # no test ran
