"""`l6470emu plot` and l6470emu.plot: every trace format the program reads becomes a picture
with something in it (read back as pixels), PNG and SVG, chosen chips and windows, live
recordings, and every bad input is one line on standard error with exit status 2.
Run by ctest's `plot` test, which is skipped (with the reason) when matplotlib is missing."""
import os
import shlex
import shutil
import subprocess
from pathlib import Path

import matplotlib
import matplotlib.image
import numpy as np
import pytest

import l6470emu
import l6470emu.plot

matplotlib.use("Agg")

FIXTURES = Path(os.environ.get("L6470EMU_SOURCE_DIR", Path(__file__).resolve().parents[2])) / "fixtures" / "traces"


def run_plot(*args):
    return subprocess.run([l6470emu.program(), "plot", *map(str, args)], capture_output=True, text=True, timeout=120)


def distinct_colours_inside(png: Path) -> int:
    """Distinct colours in the middle of the picture (inside the axes, away from the labels)."""
    pixels = matplotlib.image.imread(str(png))
    h, w = pixels.shape[:2]
    inside = pixels[h // 10: h * 9 // 10, w // 5: w * 9 // 10, :3]
    quantised = np.round(inside.reshape(-1, 3) * 31).astype(np.int32)
    return len({tuple(c) for c in quantised})


@pytest.mark.parametrize("fixture", [
    "three_chips.trace", "single_chip.trace", "saleae_logic2.csv", "saleae_logic2_decimal_no_duration.csv",
    "umockdev_spidev.ioctl", "ftrace_spi_set_cs.txt", "ftrace_trace_cmd_report.txt", "sigrok_spi.json",
])
def test_every_trace_format_becomes_a_picture_with_lines_in_several_colours(tmp_path, fixture):
    out = tmp_path / "plot.png"
    # Two of them the emulator does not reproduce (ftrace: the SW and thermal events are not in
    # it; umockdev: no times): those exit 1 unless the divergence is accepted.
    r = run_plot(FIXTURES / fixture, "-o", out, "--accept-divergence")
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 20_000
    assert distinct_colours_inside(out) >= 6


def test_the_three_chip_picture_shows_three_chips_positions_and_pins(tmp_path):
    fig = l6470emu.plot.figure(FIXTURES / "three_chips.trace")
    pos_ax, speed_ax, pin_ax = fig.axes
    assert [t.get_text() for t in pos_ax.get_legend().get_texts()] == [
        "chip 0 L6470 (1/128)", "chip 1 L6470 (1/128)", "chip 2 L6470 (1/128)"]
    assert [t.get_text() for t in pin_ax.get_yticklabels()][:3] == ["BUSY0", "FLAG0", "SW0"]
    assert len(pin_ax.get_lines()) == 9  # BUSY, FLAG, SW per chip
    assert any(text.get_text().startswith("GoUntil") for text in pos_ax.texts)  # command labels


def test_an_svg_is_written_when_the_name_says_svg(tmp_path):
    out = tmp_path / "plot.svg"
    r = run_plot(FIXTURES / "single_chip.trace", "-o", out)
    assert r.returncode == 0, r.stderr
    text = out.read_text()
    assert "<svg" in text and "ABS_POS" in text


def test_chosen_chips_and_window_are_the_only_ones_drawn(tmp_path):
    fig = l6470emu.plot.figure(FIXTURES / "three_chips.trace", chips=[2], start=0.01, end=0.03)
    pos_ax = fig.axes[0]
    assert [t.get_text() for t in pos_ax.get_legend().get_texts()] == ["chip 2 L6470 (1/128)"]
    assert pos_ax.get_xlim() == pytest.approx((10.0, 30.0))  # milliseconds
    out = tmp_path / "window.png"
    r = run_plot(FIXTURES / "three_chips.trace", "-o", out, "--chips", "0,2", "--from", "0.01", "--to", "0.03")
    assert r.returncode == 0, r.stderr
    assert distinct_colours_inside(out) >= 4


def test_a_live_recording_is_drawn_from_the_chain(tmp_path):
    chain = l6470emu.Chain(["L6470", "L6480"], record=True)
    chain.move(1, forward=True, n_step=3200)
    chain.advance(seconds=0.5)
    out = l6470emu.plot.plot(chain, tmp_path / "live.png")
    assert out.stat().st_size > 20_000
    assert distinct_colours_inside(out) >= 4


def test_a_long_run_is_bounded_and_keeps_its_extremes():
    chain = l6470emu.Chain("L6470", record=True)
    for i in range(300):
        chain.move(0, forward=i % 2 == 0, n_step=3200)
        chain.advance(seconds=0.4)
    m = l6470emu.motion(chain.trace, max_points=400)
    c = m.chips[0]
    assert len(c) <= 400
    assert max(c.abs_pos) == 3200 and min(c.abs_pos) == 0
    assert len(c.commands) == 300


@pytest.mark.parametrize("args, says", [
    (["missing.trace", "-o", "x.png"], "missing.trace: no such file"),
    (["{three}", "-o", "x.png", "--chips", "x"], "--chips 'x'"),
    (["{three}", "-o", "x.png", "--chips", "7"], "chip 7: the chain has 3 chips"),
    (["{three}", "-o", "x.png", "--chips", "3-1"], "--chips '3-1'"),
    (["{three}", "-o", "x.png", "--number-from", "x"], "--number-from 'x': write miso"),
    (["{three}", "-o", "x.png", "--from", "0.5", "--to", "0.2"], "the window is empty"),
    (["{three}", "-o", "x.png", "--from", "1000"], "the window is empty"),
    (["{three}", "-o", "x.png", "--from", "soon"], "--from"),
    (["{three}", "-o", "x.jpg"], "x.jpg: the picture is written as .png or .svg"),
    (["{three}"], "--output"),
    ([], "required"),
    (["{three}", "-o", "/nonexistent-dir/x.png"], "No such file or directory"),
    (["{garbage}", "-o", "x.png"], "unknown trace format"),
    (["{three}", "-o", "x.png", "--max-points", "4611686018427387904"], "--max-points 4611686018427387904: from 64 to 100000"),
    (["{three}", "-o", "x.png", "--max-points", "10000000"], "--max-points 10000000: from 64 to 100000"),
    (["{three}", "-o", "x.png", "--max-frames", "10"], "three_chips.trace:"),
    (["{three}", "-o", "x.png", "--max-frames", "-1"], "--max-frames -1: a number of frames"),
])
def test_bad_input_is_one_line_and_exit_status_2(tmp_path, args, says):
    garbage = tmp_path / "garbage.bin"
    garbage.write_bytes(b"\x00\x01 not a trace\n")
    args = [a.format(three=FIXTURES / "three_chips.trace", garbage=garbage) for a in args]
    args = [str(tmp_path / a) if a.endswith((".png", ".jpg")) and not a.startswith("/") else a for a in args]
    r = run_plot(*args)
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert "Traceback" not in r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert lines[0].startswith("l6470emu plot: ") and says in lines[0], lines[0]


def test_chips_numbered_from_the_mosi_end_are_labelled_so_and_the_picture_says_which_end():
    fig = l6470emu.plot.figure(FIXTURES / "three_chips.trace", chips=[0], number_from="mosi")
    assert any("count from the MOSI end" in t.get_text() for t in fig.texts)
    labels = [line.get_label() for line in fig.axes[0].get_lines() if not line.get_label().startswith("_")]
    assert labels == ["chip 0 L6470 (1/128)"]


def test_the_cli_is_quiet_but_for_its_result_when_standard_error_is_not_a_terminal(tmp_path):
    out = tmp_path / "quiet.png"
    r = run_plot(FIXTURES / "three_chips.trace", "-o", out)
    assert r.returncode == 0, r.stderr
    assert r.stderr == f"l6470emu plot: wrote {out}\n"  # no bar, no carriage return, no escape
    assert r.stdout == ""


@pytest.mark.skipif(shutil.which("script") is None, reason="needs util-linux script (a terminal to draw on)")
def test_on_a_terminal_the_cli_draws_reading_replaying_and_drawing_then_clears_the_line(tmp_path):
    out = tmp_path / "tty.png"
    command = shlex.join([l6470emu.program(), "plot", str(FIXTURES / "three_chips.trace"), "-o", str(out)])
    # script runs the command on a pseudo-terminal and copies what it printed to its output.
    r = subprocess.run(["script", "-qec", command, "/dev/null"], capture_output=True, timeout=120,
                       stdin=subprocess.DEVNULL)
    seen = r.stdout.decode()  # as bytes first: text mode would turn every '\r' into a newline
    assert r.returncode == 0, seen
    assert "\rreading three_chips.trace [" in seen, seen
    assert "\rreplaying three_chips.trace [" in seen and "% 1896 B of 1896 B" in seen, seen  # a bar with a total
    assert "\rdrawing tty.png" in seen, seen
    # The bar is taken off the line before the result is printed.
    assert f"\r\x1b[Kl6470emu plot: wrote {out}" in seen, seen
    assert out.stat().st_size > 20_000


def test_a_capture_the_model_does_not_reproduce_is_marked_and_the_exit_status_says_so(tmp_path):
    out = tmp_path / "diverged.png"
    r = run_plot(FIXTURES / "ftrace_spi_set_cs.txt", "-o", out)
    assert r.returncode == 1, r.stderr
    assert out.stat().st_size > 20_000  # the picture is still written
    assert "does not reproduce" in r.stderr and "frame 23 at t=1523.803136 s: chip 0" in r.stderr
    assert "--accept-divergence accepts it" in r.stderr
    fig = l6470emu.plot.figure(FIXTURES / "ftrace_spi_set_cs.txt")
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert any(t.startswith("DIVERGED at t=1523.803136 s (chip 0)") and "model" in t for t in texts), texts
    assert any(t.startswith("first divergence: chip 0: MISO byte 0 expected 0xF0") for t in texts), texts
    # A trace the emulator reproduces: no banner, exit 0.
    r = run_plot(FIXTURES / "homing_axis.trace", "-o", tmp_path / "homing.png")
    assert r.returncode == 0 and "does not reproduce" not in r.stderr, r.stderr
    clean = l6470emu.plot.figure(FIXTURES / "homing_axis.trace")
    assert not any("DIVERGED" in t.get_text() for ax in clean.axes for t in ax.texts)
    # The homing capture without its board: the switch never closes, and the picture says where.
    r = run_plot(FIXTURES / "homing_axis_saleae.csv", "-o", tmp_path / "bare.png")
    assert r.returncode == 1 and "BUSY" not in r.stdout, r.stderr
    r = run_plot(FIXTURES / "homing_axis_saleae.csv", "-o", tmp_path / "rig.png", "--chain",
                 "chips=L6470 axis.0=stops=-6400..300000,start=51200,switch=home@0:below:hyst=64")
    assert r.returncode == 0 and "does not reproduce" not in r.stderr, r.stderr
def label_boxes(fig, dpi):
    """The command labels' boxes in pixels, as drawn at `dpi` (the layout runs at each drawing)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    fig.set_dpi(dpi)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    return [(t.get_text(), t.get_window_extent(renderer)) for t in fig.axes[0].texts]


def overlapping(boxes):
    return [(a, b) for i, (a, p) in enumerate(boxes) for b, q in boxes[i + 1:]
            if p.x0 < q.x1 and q.x0 < p.x1 and p.y0 < q.y1 and q.y0 < p.y1]


def test_labels_of_commands_sent_at_the_same_instant_do_not_overlap(tmp_path):
    # Three chips set up one after the other (6 us apart) and started by the same frames: nine
    # commands, the three Moves at one tick.
    chain = l6470emu.Chain(["L6470"] * 3, record=True)
    for chip in range(3):
        chain.set_param(chip, "ACC", 0x200)
        chain.set_param(chip, "MAX_SPEED", 0x30)
    n_step = [1000, 2000, 3000]
    chain.frame(bytes([0x41, 0x40, 0x41]))  # Move(FWD), Move(REV), Move(FWD): byte k to chip k
    for shift in (16, 8, 0):
        chain.frame(bytes((n >> shift) & 0xFF for n in n_step))
    chain.advance(seconds=0.3)
    moves = [m.tick for c in l6470emu.motion(chain.trace).chips for m in c.commands if m.name.startswith("Move")]
    assert len(moves) == 3 and len(set(moves)) == 1  # three commands at the same instant
    for size, dpi in (((10.0, 7.5), 100), ((10.0, 7.5), 72), ((5.0, 4.0), 150)):  # 72: what an SVG uses
        fig = l6470emu.plot.figure(chain, size=size)
        boxes = label_boxes(fig, dpi)
        assert sorted(text for text, _ in boxes) == sorted(
            ["Move(FWD)", "Move(REV)", "Move(FWD)"] + ["SetParam(ACC)", "SetParam(MAX_SPEED)"] * 3)
        assert overlapping(boxes) == [], (size, dpi)
    # The trace fixtures' labels too (three_chips.trace sets up three chips in one burst).
    for fixture in ("three_chips.trace", "single_chip.trace"):
        boxes = label_boxes(l6470emu.plot.figure(FIXTURES / fixture), 100)
        assert len(boxes) >= 2 and overlapping(boxes) == [], fixture
    # And the SVG is drawn with the same layout: its labels are where the layout put them.
    out = l6470emu.plot.plot(chain, tmp_path / "burst.svg")
    assert out.read_text().count("SetParam(MAX_SPEED)") == 3  # (in the text elements' ids/comments)


def test_a_window_ending_on_its_last_event_shows_the_final_busy_edge_with_time_after_it():
    fig = l6470emu.plot.figure(FIXTURES / "three_chips.trace")
    m = l6470emu.motion(str(FIXTURES / "three_chips.trace"))
    chip1 = m.chips[1]
    last_rise = max(tick for tick, before, after in zip(chip1.ticks[1:], chip1.busy, chip1.busy[1:])
                    if after and not before)
    # The trace ends on this edge (BUSY1 rising as chip 1's move ends) and a GetStatus after it.
    assert 0 <= m.end - last_rise <= 0.001 * (m.end - m.start)
    lo, hi = fig.axes[2].get_xlim()
    edge_ms, end_ms = last_rise / l6470emu.TICKS_PER_SECOND * 1e3, m.end / l6470emu.TICKS_PER_SECOND * 1e3
    assert hi - edge_ms >= 0.03 * (end_ms - lo)  # room after the edge
    # BUSY1 is drawn high from its edge to the window's end (a chip at rest stays as it was).
    busy1 = [line for line in fig.axes[2].get_lines()][3]
    x, y = busy1.get_data()
    assert x[-1] == pytest.approx(hi) and x[-2] == pytest.approx(edge_ms)
    assert y[-1] == y[-2] == max(y) and y[-3] == min(y) < max(y)
    # A window given an end is drawn exactly (see test_chosen_chips_and_window_are_the_only_ones_drawn).
    fig = l6470emu.plot.figure(FIXTURES / "three_chips.trace", end=m.end / l6470emu.TICKS_PER_SECOND)
    assert fig.axes[2].get_xlim()[1] == pytest.approx(end_ms)


def polling_run(moves, n_step, pause):
    """A 1-chip run as a driver makes it: a move, GetStatus every millisecond until BUSY rises, a pause."""
    chain = l6470emu.Chain("L6470", record=True)
    chain.get_status(0)
    for i in range(moves):
        chain.move(0, forward=i % 2 == 0, n_step=n_step * (i + 1 if n_step > 1000 else 1))
        while not chain.busy_pin(0):  # BUSY is low while the move runs
            chain.advance(seconds=0.001)
            chain.get_status(0)
        chain.advance(seconds=pause)
        chain.get_status(0)
    return chain


def test_a_one_chip_svg_of_a_typical_run_stays_under_300_kB(tmp_path):
    # Six moves over 7.4 s polled every millisecond (was 402 kB: a filled pin lane drew every sample).
    out = l6470emu.plot.plot(polling_run(6, 25600, 0.05), tmp_path / "typical.svg")
    assert out.stat().st_size <= 300_000, out.stat().st_size
    assert "<image" not in out.read_text()  # all vectors still
    # 2000 short moves, BUSY toggling 4000 times, 100 000 samples (was 10 MB): the dense parts are
    # images, the rest vectors.
    out = l6470emu.plot.plot(polling_run(2000, 64, 0.002), tmp_path / "dense.svg", max_points=100_000)
    assert out.stat().st_size <= 300_000, out.stat().st_size
    text = out.read_text()
    assert "<image" in text and "ABS_POS" in text


def test_a_pin_is_drawn_with_a_point_per_edge_and_the_same_steps():
    t = np.array([0.0, 1, 2, 3, 4, 5, 6])
    levels = [1, 1, 0, 0, 0, 1, 1]
    tp, lp = l6470emu.plot._pin_steps(t, levels)
    assert list(tp) == [0, 2, 5, 6] and list(lp) == [1, 0, 1, 1]
    # The same level at every instant, read as steps-post.
    for x in np.linspace(0, 6, 61):
        assert lp[np.searchsorted(tp, x, side="right") - 1] == levels[np.searchsorted(t, x, side="right") - 1]
