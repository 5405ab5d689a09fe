"""l6470emu.motion(): what the chips of a trace did, as series in the datasheet's units, from a
Trace, a live recording or any trace file; chosen chips and windows; mistakes as ValueError."""
from pathlib import Path

import pytest

import l6470emu

FIXTURES = Path(__file__).resolve().parents[2] / "fixtures" / "traces"


def test_a_recorded_move_is_sampled_to_its_exact_end():
    chain = l6470emu.Chain("L6470", record=True)
    chain.move(0, forward=True, n_step=128000)  # 1000 full steps: long enough to reach MAX_SPEED
    chain.advance(seconds=2)
    m = l6470emu.motion(chain.trace, end=chain.now_seconds)  # the trace's last event is the Move
    c = m.chips[0]
    assert len(c.ticks) == len(c.abs_pos) == len(c.speed) == len(c.busy) == len(c.flag) == len(c.sw)
    assert c.ticks == sorted(c.ticks)
    assert c.abs_pos[-1] == 128000 and c.speed[-1] == 0 and c.busy[-1]
    assert max(c.speed) > 0
    phases = [p for i, p in enumerate(c.mot_status) if i == 0 or c.mot_status[i - 1] != p]
    assert phases == [0, 1, 3, 2, 0]
    assert [x.name for x in c.commands] == ["Move(FWD)"]
    assert c.commands[0].text == "Move(FWD, 128000 microsteps)"
    assert c.microsteps_per_step == 128


def test_chips_and_window_choose_what_is_sampled():
    m = l6470emu.motion(FIXTURES / "three_chips.trace", chips=[2, 0], start=0.01, end=0.02)
    assert [c.chip for c in m.chips] == [2, 0]
    assert m.start == 40_000 and m.end == 80_000
    for c in m.chips:
        assert c.ticks[0] == m.start and c.ticks[-1] == m.end


def test_chips_counted_from_the_mosi_end_are_the_chains_chips_from_the_other_end():
    m = l6470emu.motion(FIXTURES / "three_chips.trace", chips=[0], number_from="mosi")
    assert [(c.chip, c.number) for c in m.chips] == [(2, 0)]
    assert m.number_from == "mosi" and "count from the MOSI end" in m.numbering
    default = l6470emu.motion(FIXTURES / "three_chips.trace", chips=[0])
    assert [(c.chip, c.number) for c in default.chips] == [(0, 0)]
    assert "count from the MISO end" in default.numbering


def test_every_format_the_program_reads_can_be_sampled():
    for name in ("single_chip.trace", "saleae_logic2.csv", "umockdev_spidev.ioctl", "ftrace_spi_set_cs.txt",
                 "sigrok_spi.json"):
        m = l6470emu.motion(FIXTURES / name)
        assert m.chips and all(len(c) > 0 for c in m.chips), name


@pytest.mark.parametrize("kwargs, error, says", [
    ({"chips": [3]}, ValueError, "chip 3: the chain has 3 chips"),
    ({"chips": []}, ValueError, "chips: the list is empty"),
    ({"chips": "0"}, TypeError, "chips: a list"),
    ({"start": 0.5, "end": 0.1}, ValueError, "the window is empty"),
    ({"start": -1.0}, ValueError, "start = -1.0"),
    ({"end": "soon"}, TypeError, "end: seconds"),
    ({"number_from": "x"}, ValueError, "number_from: 'x' is not a chip numbering"),
])
def test_mistakes_are_value_or_type_errors_naming_them(kwargs, error, says):
    with pytest.raises(error, match=says):
        l6470emu.motion(FIXTURES / "three_chips.trace", **kwargs)


def test_a_missing_file_is_a_trace_error():
    with pytest.raises(l6470emu.TraceError):
        l6470emu.motion("/nonexistent.trace")


def progress_calls(trace, **kwargs):
    calls = []
    l6470emu.motion(trace, progress=lambda *call: calls.append(call), **kwargs)
    return calls


def test_progress_is_told_of_reading_then_replaying_each_rising_to_done_equals_total():
    for trace in (FIXTURES / "three_chips.trace", polled_recording().trace):
        calls = progress_calls(trace)
        stages = [stage for stage, *_ in calls]
        assert stages[0] == "reading" and stages[-1] == "replaying"
        assert stages == sorted(stages)  # all of reading before any of replaying
        for stage in ("reading", "replaying"):
            mine = [(done, total, unit) for s, done, total, unit in calls if s == stage]
            assert len(mine) >= 2, (stage, calls)  # when the pass begins and when it ends
            dones = [done for done, _, _ in mine]
            assert dones == sorted(dones), (stage, mine)
            done, total, unit = mine[-1]
            assert done == total > 0, (stage, mine)
            assert unit == ("bytes" if isinstance(trace, Path) else "events")


def polled_recording():
    chain = l6470emu.Chain("L6470", record=True)
    chain.move(0, forward=True, n_step=3200)
    for _ in range(5000):
        chain.get_status(0)
    return chain


def test_a_window_ending_early_still_ends_its_progress_with_done_equals_total():
    calls = progress_calls(polled_recording().trace, end=0.001)
    assert calls[-1][0] == "replaying" and calls[-1][1] == calls[-1][2] == len(polled_recording().trace)


def test_progress_calls_are_few_even_for_a_long_trace():
    calls = progress_calls(polled_recording().trace)
    assert len(calls) <= 10  # at most every 100 ms, plus each pass's start and end


def test_an_exception_raised_by_progress_ends_motion_with_it():
    class Stop(Exception):
        pass

    def stop(*_):
        raise Stop("enough")

    with pytest.raises(Stop, match="enough"):
        l6470emu.motion(FIXTURES / "three_chips.trace", progress=stop)


def test_progress_must_be_callable():
    with pytest.raises(TypeError, match="progress"):
        l6470emu.motion(FIXTURES / "three_chips.trace", progress=3)


def test_format_progress_draws_the_programs_bar():
    assert l6470emu._l6470emu.format_progress("replaying run.trace", 50, 100, "events", 60) == \
        "replaying run.trace [########--------]  50% 50 of 100 events"
