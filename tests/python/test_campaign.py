"""l6470emu.campaign() and campaign_merge() over `l6470emu campaign`, and the pytest plugin's
l6470emu_campaign marker: the verdicts of drivers written for them (tests/linux/clients/
campaign_driver), the JSON read back, the CLI's refusals as exceptions, and a marked test turned
into one case per (fault, chip, point) that fails, passes or is skipped as the CLI would judge it."""
import json
import re
import textwrap
from pathlib import Path

import pytest

import l6470emu

pytest_plugins = ["pytester"]

SOURCE_DIR = Path(__file__).resolve().parents[2]
BOARD = "chips=L6470 check=warn"  # judge the driver's own handling, not the sanitizer (docs/campaigns.md)


def built(relative: str) -> Path:
    """A program of the build tree, found next to the l6470emu program; skips the test when absent."""
    path = Path(l6470emu.program()).parent / relative
    if not path.is_file():
        print(f"skipped: {path} is not built")
        pytest.skip(f"{path} is not built (a build with the tests and examples has it)")
    return path


@pytest.fixture
def driver() -> Path:
    """tests/linux/clients/campaign_driver: careful, careless, stuck, crash or deadlock."""
    return built("tests/linux/clients/campaign_driver")


def test_a_careful_driver_detects_an_overcurrent_during_motion_and_a_careless_one_fails_silently(driver):
    careful = l6470emu.campaign([driver, "careful"], chain=BOARD, faults="ocd", at="during_motion")
    careless = l6470emu.campaign([str(driver), "careless"], chain=BOARD, faults=["ocd"], at=["during_motion"])
    assert [(r.fault, r.chip, r.point, r.verdict) for r in careful.reruns] == [("ocd", 0, "during_motion", "detected")]
    assert [(r.fault, r.chip, r.point, r.verdict) for r in careless.reruns] == \
        [("ocd", 0, "during_motion", "silent_failure")]
    assert (careful.status, careful.failed, careful.json_path) == (0, (), None)
    assert careless.status == 1 and careless.failed == careless.reruns
    assert str(careful) == "l6470emu campaign: 1 rerun: 1 detected"
    assert str(careless) == "l6470emu campaign: 1 rerun: 1 silent_failure"
    assert str(careless) in careless.output.splitlines()
    assert careless.summary["silent_failure"] == 1 and careless.complete and careless.total == 1
    failure = careless.reruns[0].first_failure
    assert (failure.what, failure.where) == ("ABS_POS", "the clean run's end")
    # Without json_path, a failing rerun's reproducing scenario stays in the temporary folder.
    assert careless.json_path is not None and Path(careless.reruns[0].reproducer).is_file()
    assert str(careless.reruns[0].reproducer) in careless.reruns[0].command


def test_the_results_reruns_are_the_json_report(driver, tmp_path):
    report_path = tmp_path / "campaign.json"
    result = l6470emu.campaign([driver, "careless"], chain=BOARD, faults="ocd,uvlo", json_path=report_path, jobs=2)
    report = json.loads(report_path.read_text())
    assert result.json_path == report_path and result.report == report
    assert len(result.reruns) == len(report["reruns"]) == report["total"] == result.total > 2
    assert result.summary == report["summary"] and result.complete == report["complete"]
    for rerun, j in zip(result.reruns, report["reruns"]):
        assert (rerun.index, rerun.fault, rerun.chain, rerun.chip) == (j["index"], j["fault"], j["chain"], j["chip"])
        assert (rerun.point, rerun.tick, rerun.seconds, rerun.after_command) == \
            (j["point"]["name"], j["point"]["tick"], j["point"]["seconds"], j["point"]["after_command"])
        assert (rerun.verdict, rerun.flag_read, rerun.traffic_differs, rerun.exit, rerun.program) == \
            (j["verdict"], j["flag_read"], j["traffic_differs"], j["exit"], j["program"])
        assert (rerun.reproducer, rerun.command) == (j["reproducer"], j["command"])
        expected_failure = j["first_failure"]
        assert (rerun.first_failure is None) == (expected_failure is None)
        if expected_failure is not None:
            assert rerun.first_failure.__dict__ == expected_failure
    assert result.failed == tuple(r for r in result.reruns if r.verdict in ("silent_failure", "hang", "deadlock", "crash"))


def test_fail_on_decides_which_reruns_fail_as_the_cli_does(driver):
    result = l6470emu.campaign([driver, "careful"], chain=BOARD, faults="ocd", at="during_motion",
                               fail_on=("detected", "silent_failure"))
    assert result.status == 1 and result.failed == result.reruns
    assert result.fail_on == ("detected", "silent_failure")
    assert not result.reruns[0].fails() and result.reruns[0].fails("detected")


def test_usage_errors_raise_value_error_naming_the_problem(driver):
    with pytest.raises(ValueError, match=r"'ocdd' is not a fault \(did you mean ocd\?\)"):
        l6470emu.campaign([driver, "careful"], chain=BOARD, faults="ocdd")
    with pytest.raises(ValueError, match="shard"):
        l6470emu.campaign([driver, "careful"], chain=BOARD, faults="ocd", shard="4/3")
    with pytest.raises(ValueError, match="exactly one of board= .* and chain="):
        l6470emu.campaign([driver], board="board.yaml", chain=BOARD)
    with pytest.raises(ValueError, match="exactly one of board="):
        l6470emu.campaign([driver])
    with pytest.raises(ValueError, match="'sometimes' is not a verdict"):
        l6470emu.campaign([driver], chain=BOARD, fail_on="sometimes")


def test_a_clean_run_that_does_not_pass_raises_campaign_error(tmp_path):
    with pytest.raises(l6470emu.CampaignError) as failed:
        l6470emu.campaign(["/bin/false"], chain=BOARD, faults="ocd", json_path=tmp_path / "c.json")
    assert failed.value.status == 6  # run's own status: the program failed
    assert "the clean run did not pass" in failed.value.output and "exit status 6" in str(failed.value)


def test_campaign_merge_of_three_shards_is_the_unsharded_report(driver, tmp_path):
    def run(folder: str, shard=None):
        (tmp_path / folder).mkdir()
        return l6470emu.campaign([driver, "careless"], chain=BOARD, faults="ocd,uvlo", shard=shard,
                                 json_path="campaign.json", cwd=tmp_path / folder)

    whole = run("whole")
    shards = [run(f"shard{k}", (k, 3)) for k in (1, 2, 3)]
    assert [s.shard for s in shards] == ["1/3", "2/3", "3/3"]
    assert sum(len(s.reruns) for s in shards) == len(whole.reruns) > 3
    merged = l6470emu.campaign_merge([tmp_path / f"shard{k}" / "campaign.json" for k in (1, 2, 3)],
                                     tmp_path / "merged.json")
    assert (tmp_path / "merged.json").read_bytes() == (tmp_path / "whole" / "campaign.json").read_bytes()
    assert (merged.reruns, merged.summary, merged.status) == (whole.reruns, whole.summary, whole.status)
    assert str(merged) == str(whole)
    with pytest.raises(ValueError):
        l6470emu.campaign_merge([tmp_path / "shard1" / "campaign.json"] * 2, tmp_path / "twice.json")


MARKED_TESTS = """
    import pytest

    DRIVER = {driver!r}

    @pytest.mark.l6470_chain("L6470", check="warn")
    @pytest.mark.l6470emu_campaign(faults=("ocd", "uvlo"), points=("during_motion", "idle_polling"))
    @pytest.mark.parametrize("mode", ["careful", "careless"])
    def test_move(spidev_board, mode):
        result = spidev_board.run([DRIVER, mode])
        assert result.stdout == "done\\n"  # the clean run's output
        assert spidev_board.campaign_case == (spidev_board.campaign_rerun.fault, 0, spidev_board.campaign_rerun.point)
        assert spidev_board.campaign_result.reruns == (spidev_board.campaign_rerun,)

    def test_plain(spidev_board):
        assert spidev_board.campaign_case is None
"""


def test_the_marker_makes_one_case_per_fault_chip_and_point(pytester, driver):
    pytester.makepyfile(test_marked=textwrap.dedent(MARKED_TESTS.format(driver=str(driver))))
    result = pytester.runpytest("-p", "l6470emu.pytest_plugin", "--collect-only", "-q")
    ids = [line for line in result.outlines if "::" in line]
    assert sorted(ids) == sorted([f"test_marked.py::test_move[{fault}-chip0-{point}-{mode}]"
                                  for mode in ("careful", "careless") for fault in ("ocd", "uvlo")
                                  for point in ("during_motion", "idle_polling")] + ["test_marked.py::test_plain"])


def test_a_careless_drivers_cases_fail_and_a_careful_ones_pass(pytester, driver):
    pytester.makepyfile(test_marked=textwrap.dedent(MARKED_TESTS.format(driver=str(driver))))
    result = pytester.runpytest("-p", "l6470emu.pytest_plugin", "-v")
    outcomes = {line.split("::")[1].split(" ")[0]: line.split(" ")[1] for line in result.outlines
                if line.startswith("test_marked.py::")}
    for fault in ("ocd", "uvlo"):
        for point in ("during_motion", "idle_polling"):
            assert outcomes[f"test_move[{fault}-chip0-{point}-careful]"] == "PASSED"
    assert outcomes["test_move[ocd-chip0-during_motion-careless]"] == "FAILED"
    assert outcomes["test_plain"] == "PASSED"
    text = result.stdout.str()
    assert "silent_failure: ocd on spidev0.0 chip 0 at during_motion" in text
    assert "the program: exited with status 0" in text and "first failure: ABS_POS" in text
    assert "reproduce: l6470emu run --chain 'bus=0 cs=0 chips=L6470 time=virtual check=warn' --scenario " in text


def test_a_point_missing_from_the_clean_run_skips_the_case(pytester, driver):
    pytester.makepyfile(test_missing=textwrap.dedent(f"""
        import pytest

        @pytest.mark.l6470_chain("L6470", check="warn")
        @pytest.mark.l6470emu_campaign(faults="ocd", points=("at_Run",))
        def test_move(spidev_board):
            spidev_board.run([{str(driver)!r}, "careless"])
    """))
    result = pytester.runpytest("-p", "l6470emu.pytest_plugin", "-rs")
    result.assert_outcomes(skipped=1)
    assert "has no at_Run point for chip 0: no ocd rerun" in result.stdout.str()


def test_the_marker_without_spidev_board_is_a_usage_error(pytester):
    pytester.makepyfile(test_in_process="""
        import pytest

        @pytest.mark.l6470emu_campaign(faults="ocd")
        def test_in_process(l6470_board):
            pass
    """)
    result = pytester.runpytest("-p", "l6470emu.pytest_plugin")
    assert result.ret != 0
    assert "@pytest.mark.l6470emu_campaign needs the spidev_board fixture" in result.stdout.str()


def test_the_marker_refuses_unknown_keywords_and_the_cli_refuses_unknown_faults(pytester, driver):
    pytester.makepyfile(test_bad_fault=textwrap.dedent(f"""
        import pytest

        @pytest.mark.l6470emu_campaign(faults="ocdd", points="during_motion")
        def test_fault(spidev_board):
            spidev_board.run([{str(driver)!r}, "careful"])
    """), test_bad_keyword="""
        import pytest

        @pytest.mark.l6470emu_campaign(fault="ocd")
        def test_keyword(spidev_board):
            pass
    """)
    result = pytester.runpytest("-p", "l6470emu.pytest_plugin", "test_bad_fault.py")
    result.assert_outcomes(failed=1)
    assert "@pytest.mark.l6470emu_campaign: l6470emu campaign: --faults: 'ocdd' is not a fault (did you mean ocd?)" \
        in result.stdout.str()
    result = pytester.runpytest("-p", "l6470emu.pytest_plugin", "test_bad_keyword.py")
    assert result.ret != 0 and "unknown argument(s) ['fault']" in result.stdout.str()


def test_the_example_drivers_campaign_finds_its_silent_overcurrent_after_the_last_poll():
    example = built("examples/campaign_driver")
    result = l6470emu.campaign([example], chain="chips=L6470", faults="ocd", at="idle_polling,during_motion")
    verdicts = {r.point: r.verdict for r in result.reruns}
    assert verdicts["idle_polling"] == "silent_failure" and verdicts["during_motion"] == "detected"


def test_the_example_of_the_python_campaign_page_fails_and_passes_as_shown(pytester):
    example = built("examples/campaign_driver")
    page = (SOURCE_DIR / "docs" / "campaigns-python.md").read_text()
    blocks = [b for b in re.findall(r"```python\n(.*?)```", page, re.S) if "def test_" in b]
    assert len(blocks) == 1, "docs/campaigns-python.md shows one example test file"
    assert 'DRIVER = "./campaign_driver"' in blocks[0]
    pytester.makepyfile(test_driver=blocks[0].replace('"./campaign_driver"', repr(str(example))))
    result = pytester.runpytest("-p", "l6470emu.pytest_plugin", "-v")
    shown = re.findall(r"^(test_driver\.py::\S+) (PASSED|FAILED)$", page, re.M)
    assert len(shown) == 4
    for nodeid, outcome in shown:
        assert any(line.startswith(f"{nodeid} {outcome}") for line in result.outlines), (nodeid, outcome)
    assert "silent_failure: ocd on spidev0.0 chip 0 at idle_polling (0.462929 s, after GetStatus)" in result.stdout.str()
