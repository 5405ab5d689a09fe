"""Pictures of what the motors did: each chip's position, speed, BUSY/FLAG/SW pins and the
commands it received, against time, from a trace or a live recording (matplotlib, no display).

    l6470emu.plot.plot("run.trace", "run.png", chips=[0, 2], start=0.1, end=0.9)
    chain = l6470emu.Chain(["L6470"], record=True); ...; l6470emu.plot.plot(chain, "run.svg")
    python3 -m l6470emu.plot run.trace -o run.png --chips 0,2 --from 0.1 --to 0.9

The numbers come from l6470emu.motion() (the emulator's exact states, in the datasheet's
integer units); only here are they converted: ticks to seconds, SPEED to full steps per second.
ABS_POS is drawn in microsteps, as the register holds it.
"""
import argparse
import sys
from pathlib import Path
from typing import List, Optional, Sequence, Tuple, Union

from . import _l6470emu

SECONDS_PER_TICK = 1.0 / _l6470emu.TICKS_PER_SECOND
#: SPEED register units (2^-28 full step per 250 ns tick) in full steps per second.
STEPS_PER_S_PER_SPEED_UNIT = _l6470emu.TICKS_PER_SECOND / 2.0**28
#: Command labels are written next to their markers when a picture has at most this many.
MAX_LABELLED_COMMANDS = 40
#: A window with no end given is drawn this much longer (a fraction of its span) than its last
#: event, so an edge there (the final BUSY rise) is seen; chips at rest keep their state into it.
END_MARGIN = 0.04
#: A pin lane still holding more level changes than this is drawn as an image in an SVG (a
#: picture is about a thousand pixels wide), and so are the markers of a chip with more commands
#: than MAX_VECTOR_MARKERS: vectors there would only draw over each other, in megabytes.
MAX_VECTOR_EDGES = 1000
MAX_VECTOR_MARKERS = 400
#: A chip's position and speed are drawn as images in an SVG when it has more samples than this.
MAX_VECTOR_SAMPLES = 10000
#: The bounds of motion(): the most samples per chip, and the most frames a trace may hold by default.
MAX_POINTS = _l6470emu.MAX_MOTION_POINTS
DEFAULT_MAX_FRAMES = _l6470emu.DEFAULT_MAX_FRAMES
#: The file types plot() writes.
FORMATS = (".png", ".svg")

EXIT_BAD_INPUT = 2
#: The emulator does not reproduce the trace (the picture marks where); --accept-divergence makes it 0.
EXIT_DIVERGED = 1
#: What to say when matplotlib is missing.
MATPLOTLIB_MISSING = "matplotlib is not installed (Debian: apt install python3-matplotlib)"


class PlotError(ValueError):
    """A request plot() cannot draw: an unknown output type, a bad chip list."""


def parse_chips(text: str) -> List[int]:
    """A chip list as the command line gives it: "0,2", "1-3", "0,2-4" (numbered as --number-from says)."""
    chips: List[int] = []
    for part in text.split(","):
        part = part.strip()
        first, dash, last = part.partition("-")
        try:
            lo = int(first, 10)
            hi = int(last, 10) if dash else lo
        except ValueError:
            raise PlotError(f"--chips {text!r}: chip numbers separated by commas, ranges as 1-3 (e.g. 0,2-4)") from None
        if lo < 0 or hi < lo or hi > 255:
            raise PlotError(f"--chips {text!r}: {part!r} is not a chip number or range from 0 to 255")
        chips.extend(range(lo, hi + 1))
    return sorted(set(chips))


class TerminalProgress:
    """A progress bar on a terminal (standard error by default), as the l6470emu program draws
    it while replaying or converting: one line redrawn in place, cleared when done; nothing at
    all when the stream is not a terminal (a pipe, a file, a test). Pass it as progress= to
    figure(), plot() or l6470emu.motion(); stage() shows a step without a bar ("drawing").
    """

    def __init__(self, name: str, stream=None):
        self.name = name
        self.stream = stream if stream is not None else sys.stderr
        try:
            self.enabled = self.stream.isatty()
        except (AttributeError, ValueError):
            self.enabled = False
        self._drawn = False

    def __call__(self, stage: str, done: int, total: int, unit: str) -> None:
        label = f"{stage} {self.name}"
        self._draw(label if done == 0 and total == 0 else _l6470emu.format_progress(label, done, total, unit))

    def stage(self, what: str) -> None:
        """A step without a measure of its own: its name alone."""
        self._draw(what)

    def clear(self) -> None:
        """Takes the bar off the line (before other output, and at the end)."""
        if self.enabled and self._drawn:
            self.stream.write("\r\x1b[K")
            self.stream.flush()
        self._drawn = False

    def _draw(self, line: str) -> None:
        if not self.enabled:
            return
        self.stream.write("\r" + line + "\x1b[K")
        self.stream.flush()
        self._drawn = True


def _motion_of(source, chain, chips, start, end, format, select, max_points, number_from, progress=None,
               max_frames=DEFAULT_MAX_FRAMES, board=None):
    """l6470emu.motion() of a Motion (as is), a Chain recording into memory, a Trace or a path."""
    if isinstance(source, _l6470emu.Motion):
        return source
    if isinstance(source, _l6470emu.Chain):
        if source.trace is None and source.record_path is None:
            raise PlotError("the Chain records nothing: make it with record=True (or record=PATH)")
        if end is None and source.now_seconds > (start or 0.0):
            end = source.now_seconds  # a live chain: up to its present
        source = source.trace if source.trace is not None else source.record_path
    return _l6470emu.motion(source, chain, format=format, select=select, chips=chips, start=start, end=end,
                            max_points=max_points, number_from=number_from, progress=progress,
                            max_frames=max_frames, board=board)


def _time_scale(motion) -> tuple:
    span = (motion.end - motion.start) * SECONDS_PER_TICK
    if span < 0.01:
        return 1e6, "µs"
    if span < 2:
        return 1e3, "ms"
    return 1.0, "s"


def _pin_steps(t, levels):
    """The samples of a pin drawn as steps (each level held until the next sample) that change
    what is drawn: the first, each one whose level differs from the one before, and the last.
    The same picture exactly, with one point per edge instead of one per sample."""
    import numpy as np
    levels = np.asarray(levels, dtype=np.float64)
    if len(levels) <= 2:
        return np.asarray(t, dtype=np.float64), levels
    keep = np.empty(len(levels), dtype=bool)
    keep[0] = keep[-1] = True
    keep[1:-1] = levels[1:-1] != levels[:-2]
    return np.asarray(t, dtype=np.float64)[keep], levels[keep]


def _command_labels(ax, notes):
    """Writes the command labels (x, y, text, colour) beside their markers and keeps any two
    from overlapping, whatever the size, resolution or output type (see _LabelLayout)."""
    texts = [ax.annotate(text, (x, y), xytext=(4, 6), textcoords="offset points", fontsize=7, color=colour,
                         annotation_clip=False)
             for x, y, text, colour in sorted(notes, key=lambda n: n[0])]
    for t in texts:
        t.set_in_layout(False)  # the layout below moves them; the axes' size must not follow
    ax.add_artist(_LabelLayout(texts))


def _label_layout_artist():
    from matplotlib.artist import Artist

    class LabelLayout(Artist):
        """Places command labels when the figure is drawn, in the renderer's own pixels (so for
        any size, resolution and file type), so that no two labels' boxes meet: in time order,
        each takes the free place nearest its marker, above or under it, inside the axes if it can.
        Drawn before the labels (lowest zorder); draws nothing itself."""
        zorder = -1e9

        def __init__(self, texts):
            super().__init__()
            self.texts = texts
            self.set_in_layout(False)

        def draw(self, renderer):
            if not self.texts:
                return
            ax = self.axes
            inside = ax.get_window_extent(renderer)
            to_px = renderer.points_to_pixels(1.0)  # pixels per point
            gap = 1.5 * to_px  # pixels kept free between two labels
            placed = []  # (x0, y0, x1, y1) in pixels
            for text in self.texts:
                text.xyann = (4, 6)
                box = text.get_window_extent(renderer)  # its place 6 points above its marker
                _, ay = ax.transData.transform(text.xy)
                down = (ay - 6 * to_px) - box.y1  # the shift putting it as far under the marker
                # Where it may go: its own place, under the marker, or just above or under a
                # label already placed; the nearest free one, inside the axes if one is.
                shifts = {0.0, down}
                for p in placed:
                    shifts.update((p[3] + gap - box.y0, p[1] - gap - box.y1))

                def cost(shift):
                    r = (box.y0 + shift, box.y1 + shift)
                    outside = not (inside.y0 <= r[0] and r[1] <= inside.y1)
                    return (outside, shift if shift >= 0 else down - shift + 0.5)

                choice = None
                for shift in sorted((x for x in shifts if x >= 0 or x <= down), key=cost):
                    r = (box.x0, box.y0 + shift, box.x1, box.y1 + shift)
                    g = 0.99 * gap  # (a place computed to be `gap` away is not lost to rounding)
                    if not any(r[0] < p[2] + g and p[0] < r[2] + g and r[1] < p[3] + g and p[1] < r[3] + g
                               for p in placed):
                        choice = shift
                        break
                # (Just above the highest label placed is always free, so a place is found.)
                placed.append((box.x0, box.y0 + choice, box.x1, box.y1 + choice))
                text.xyann = (4, 6 + choice / to_px)
            self.stale = False

    return LabelLayout


def _LabelLayout(texts):
    return _label_layout_artist()(texts)


def figure(source, *, chain=None, chips: Optional[Sequence[int]] = None, start: Optional[float] = None,
           end: Optional[float] = None, format: Optional[str] = None, select: str = "", max_points: int = 4000,
           title: Optional[str] = None, size=(10.0, 7.5), position_unit: Optional[Tuple[str, float]] = None,
           number_from: str = "miso", progress=None, max_frames: int = DEFAULT_MAX_FRAMES, board=None):
    """The picture as a matplotlib Figure (not shown, not saved; pyplot is not used).

    source: a trace file (any format the l6470emu program reads), a Trace, a Chain made with
    record=True, or a Motion from l6470emu.motion() (which brings its own numbering). The other
    arguments are motion()'s (number_from: chip 0 at the "miso" or the "mosi" end; chain and
    board: the world a capture runs through), and position_unit = (name, microsteps per unit),
    e.g. ("rev", 25600), to draw positions in another unit than ABS_POS's microsteps. progress:
    motion()'s progress(stage, done, total, unit), e.g. a TerminalProgress, told how far reading
    and replaying the trace have come.

    Where the emulator does not reproduce the trace (motion().divergence), the picture says so: a
    red line at the first divergence with what differed, the time after it shaded, and a banner
    that what follows is the emulator's model, not the capture. The Motion drawn is the
    figure's `motion` attribute.
    """
    import numpy as np
    from matplotlib.figure import Figure

    motion = _motion_of(source, chain, chips, start, end, format, select, max_points, number_from, progress,
                        max_frames, board)
    scale, unit = _time_scale(motion)
    pos_unit, per_unit = position_unit if position_unit is not None else ("microsteps", 1.0)
    if not per_unit > 0:
        raise PlotError(f"position_unit {position_unit!r}: microsteps per unit must be positive")
    fig = Figure(figsize=size, layout="constrained")
    pos_ax, speed_ax, pin_ax = fig.subplots(3, 1, sharex=True, height_ratios=[3, 2, 2])
    colours = [f"C{i % 10}" for i in range(len(motion.chips))]
    x_start, x_end = motion.start * SECONDS_PER_TICK * scale, motion.end * SECONDS_PER_TICK * scale
    # A window given an end is drawn as given; one ending on the last event gets a margin after it.
    # (A Motion brings its own window, which may end before the next command.)
    margin = END_MARGIN * (x_end - x_start) if end is None and not isinstance(source, _l6470emu.Motion) else 0.0
    x_end += margin
    total_commands = sum(len(c.commands) for c in motion.chips)
    labels: List[str] = []
    notes: List[tuple] = []  # command labels: (x, y, text, colour)
    for n, (c, colour) in enumerate(zip(motion.chips, colours)):
        t = np.asarray(c.ticks, dtype=np.float64) * SECONDS_PER_TICK * scale
        pos = np.asarray(c.abs_pos, dtype=np.float64) / per_unit
        speed = np.asarray(c.speed, dtype=np.float64) * STEPS_PER_S_PER_SPEED_UNIT
        name = f"chip {c.number} {c.variant} (1/{c.microsteps_per_step})"
        # In the margin past the last event a chip at rest stays as it was (nothing moves it).
        held = margin > 0 and len(t) > 0 and c.speed[-1] == 0
        t_held = np.append(t, x_end) if held else t
        dense = len(t) > MAX_VECTOR_SAMPLES  # (--max-points above it) many samples to a pixel column
        pos_ax.plot(t_held, np.append(pos, pos[-1]) if held else pos, color=colour, linewidth=1.6, label=name,
                    rasterized=dense)
        speed_ax.plot(t_held, np.append(speed, speed[-1]) if held else speed, color=colour, linewidth=1.4,
                      rasterized=dense)
        if c.commands and len(t):
            ct = np.asarray([m.tick for m in c.commands], dtype=np.float64) * SECONDS_PER_TICK * scale
            cp = np.interp(ct, t, pos)
            pos_ax.plot(ct, cp, linestyle="none", marker="v", markersize=7, color=colour,
                        markeredgecolor="black", markeredgewidth=0.6, zorder=3,
                        rasterized=len(ct) > MAX_VECTOR_MARKERS)  # overprinted: an image in an SVG
            notes.extend((x, y, m.name, colour) for x, y, m in zip(ct, cp, c.commands))
        # The pins as logic traces, one lane per pin (high = the upper edge of the lane, shaded).
        for k, (pin, levels) in enumerate((("BUSY", c.busy), ("FLAG", c.flag), ("SW", c.sw))):
            lane = 3.0 * (len(motion.chips) - 1 - n) + (2 - k)
            tp, levels = _pin_steps(t_held, list(levels) + ([levels[-1]] if held else []))
            y = lane + 0.1 + 0.7 * levels
            dense = len(tp) > MAX_VECTOR_EDGES  # an edge per pixel column or more: an image in an SVG
            pin_ax.plot(tp, y, drawstyle="steps-post", color=colour, linewidth=1.2, rasterized=dense)
            pin_ax.fill_between(tp, lane + 0.1, y, step="post", color=colour, alpha=0.2, linewidth=0,
                                rasterized=dense)
            labels.append((lane + 0.45, f"{pin}{c.number}"))
    if total_commands <= MAX_LABELLED_COMMANDS:
        _command_labels(pos_ax, notes)  # labels of commands close in time stacked, never overprinted
    pos_ax.set_ylabel(f"ABS_POS ({pos_unit})")
    pos_ax.legend(loc="best", fontsize=8)
    pos_ax.grid(True, alpha=0.3)
    speed_ax.set_ylabel("speed (full step/s,\nnegative = reverse)")
    speed_ax.axhline(0, color="0.6", linewidth=0.6)
    speed_ax.grid(True, alpha=0.3)
    pin_ax.set_yticks([y for y, _ in labels], [name for _, name in labels], fontsize=7)
    pin_ax.set_ylabel("pins (high / low)")
    pin_ax.grid(True, axis="x", alpha=0.3)
    pin_ax.set_xlabel(f"time ({unit})")
    pin_ax.set_xlim(x_start, x_end)
    if title is None:
        name = source if isinstance(source, (str, Path)) else getattr(source, "name", None)
        title = f"{Path(name).name if isinstance(name, (str, Path)) else 'recording'}: chain {motion.chain}"
        if total_commands > MAX_LABELLED_COMMANDS:
            title += f" ({total_commands} commands: markers only)"
    fig.suptitle(title, fontsize=11)
    # Which end chip 0 is at, once, under the picture (and a description the user gave instead
    # of the trace's own).
    small_print = motion.numbering + (f"; {motion.overridden}" if motion.overridden else "")
    fig.text(0.005, 0.002, small_print, fontsize=7, color="0.35", ha="left", va="bottom")
    if motion.divergence is not None:
        _mark_divergence(fig, (pos_ax, speed_ax, pin_ax), motion, scale, unit)
    fig.motion = motion
    return fig


def divergence_text(motion) -> str:
    """One line about where the emulator first parts from the trace ("" when it does not)."""
    d = motion.divergence
    if d is None:
        return ""
    more = motion.frames_diverged + motion.pins_diverged - 1
    return (f"{d.summary}" + (f" (and {more} more differences)" if more > 0 else ""))


def _mark_divergence(fig, axes, motion, scale, unit) -> None:
    """The first divergence: a red line with what differed, the model's part shaded, a banner."""
    d = motion.divergence
    x = d.tick * SECONDS_PER_TICK * scale
    right = motion.end * SECONDS_PER_TICK * scale
    for ax in axes:
        ax.axvline(x, color="red", linewidth=1.4, zorder=4)
        if x < right:
            ax.axvspan(x, right, color="red", alpha=0.06, linewidth=0, zorder=0)
    chip = "bytes past the chain" if d.chip is None else f"chip {d.chip}"
    axes[0].annotate(f"first divergence: {chip}: {d.what}", (x, 1.0), xycoords=("data", "axes fraction"),
                     xytext=(4, -12), textcoords="offset points", fontsize=7, color="red", va="top")
    axes[0].text(0.5, 0.03, f"DIVERGED at t={d.seconds:.6f} s ({chip}): from the red line on, this is the "
                 "emulator's model of the run, not what the trace holds", transform=axes[0].transAxes, fontsize=8.5,
                 color="white", ha="center", va="bottom", zorder=5,
                 bbox=dict(facecolor="red", edgecolor="none", boxstyle="round,pad=0.3"))


def plot(source, output: Union[str, Path], **options) -> Path:
    """Draws the picture of `source` (see figure()) into `output`, a .png or .svg file. A
    progress with a stage() method (TerminalProgress) is also told when the drawing begins."""
    output = Path(output)
    if output.suffix.lower() not in FORMATS:
        raise PlotError(f"{output}: the picture is written as .png or .svg (the file name says which)")
    dpi = options.pop("dpi", 100)
    fig = figure(source, **options)
    progress = options.get("progress")
    if hasattr(progress, "stage"):
        progress.stage(f"drawing {output.name}")
    fig.savefig(output, dpi=dpi)
    plot.last_motion = fig.motion  # what was drawn (main() reads its divergence)
    return output


plot.last_motion = None


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line and exit status 2, not the usage text
        raise PlotError(message)


def _arguments(argv):
    p = _Parser(
        prog="l6470emu plot",
        description="Draw each chip's position, speed, BUSY/FLAG/SW and commands against time, from a trace.")
    p.add_argument("trace", help="trace file: native, Saleae CSV, umockdev .ioctl, ftrace text, sigrok JSON, VCD or .sr")
    p.add_argument("-o", "--output", required=True, help="picture to write: .png or .svg")
    p.add_argument("--chips", help="chips to draw: 0,2 or 1-3 (default all; numbered as --number-from says)")
    p.add_argument("--number-from", default="miso",
                   help="chip 0 is the chip driving MISO (miso, the default) or the one reading the host's MOSI (mosi)")
    p.add_argument("--from", dest="start", type=float,
                   help="window start, seconds from the trace's start (a capture's own clock counts from 0 here)")
    p.add_argument("--to", dest="end", type=float,
                   help="window end, seconds (default: the trace's end, plus up to 1 s while a move goes on, "
                        "drawn 4%% longer)")
    p.add_argument("--chain", help="the emulated chain (3, 2*L6470,L6480), or the board description of one chain "
                   "(\"chips=L6470 axis.0=stops=0..256000,switch=home@0\"); default: the trace's own")
    p.add_argument("--board", help="a file with the board description of one chain to run a capture through "
                   "(replaces the trace's own; the picture says so)")
    p.add_argument("--accept-divergence", action="store_true",
                   help="exit 0 even when the emulator does not reproduce the trace (the picture still marks it)")
    p.add_argument("--format", default=None, help="input format (default: recognised from the content)")
    p.add_argument("--select", default="", help="the stream to take when the file has several")
    p.add_argument("--max-points", type=int, default=4000,
                   help=f"most samples per chip (default 4000, at most {MAX_POINTS})")
    p.add_argument("--max-frames", type=int, default=DEFAULT_MAX_FRAMES,
                   help=f"the most frames the trace may hold (default {DEFAULT_MAX_FRAMES}; 0 = no limit)")
    p.add_argument("--title", help="the picture's title (default: the file and the chain)")
    p.add_argument("--size", default="10x7.5", help="width x height in inches (default 10x7.5)")
    p.add_argument("--dpi", type=int, default=100,
                   help="PNG resolution, and of the images an SVG embeds for dense series (default 100)")
    return p.parse_args(argv)


def available() -> bool:
    """Whether pictures can be drawn here (matplotlib can be imported)."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True


def main(argv: Optional[Sequence[str]] = None) -> int:
    """`l6470emu plot` / `python3 -m l6470emu.plot`: 0, or 2 with one line on standard error."""
    try:
        args = _arguments(argv)
        try:
            width, height = (float(x) for x in args.size.lower().split("x"))
            if not (0 < width <= 100 and 0 < height <= 100):
                raise ValueError
        except ValueError:
            raise PlotError(f"--size {args.size!r}: WIDTHxHEIGHT in inches, e.g. 10x7.5") from None
        if args.max_points < 64 or args.max_points > MAX_POINTS:
            raise PlotError(f"--max-points {args.max_points}: from 64 to {MAX_POINTS} "
                            "(samples per chip; a picture has a few thousand columns)")
        if args.max_frames < 0:
            raise PlotError(f"--max-frames {args.max_frames}: a number of frames, 0 for no limit")
        if args.dpi < 10 or args.dpi > 1200:
            raise PlotError(f"--dpi {args.dpi}: from 10 to 1200")
        if args.number_from.lower() not in ("miso", "mosi"):
            raise PlotError(f"--number-from {args.number_from!r}: write miso (chip 0 drives MISO) or mosi "
                            "(chip 0 reads the host's MOSI)")
        chips = parse_chips(args.chips) if args.chips is not None else None
        if not Path(args.trace).exists():
            raise PlotError(f"{args.trace}: no such file")
        if not available():
            raise PlotError(f"drawing needs matplotlib: {MATPLOTLIB_MISSING}")
        import matplotlib
        matplotlib.use("Agg")
        # A bar on a terminal while a long trace is read, replayed and drawn; quiet otherwise.
        # The file's name alone: a long path cut to fit would cut the stage's name too.
        bar = TerminalProgress(Path(args.trace).name)
        try:
            if args.chain is not None and args.board is not None:
                raise PlotError("--chain and --board both describe the chain: give one of them")
            out = plot(args.trace, args.output, chain=args.chain, board=args.board, chips=chips, start=args.start,
                       end=args.end, format=args.format, select=args.select, max_points=args.max_points,
                       max_frames=args.max_frames, title=args.title,
                       size=(width, height), dpi=args.dpi, number_from=args.number_from, progress=bar)
        finally:
            bar.clear()
    except (ValueError, TypeError, OSError, RuntimeError) as e:  # TraceError is a ValueError
        print(f"l6470emu plot: {e}", file=sys.stderr)
        return EXIT_BAD_INPUT
    print(f"l6470emu plot: wrote {out}", file=sys.stderr)
    motion = plot.last_motion
    if motion is not None and motion.overridden:
        print(f"note: {motion.overridden}", file=sys.stderr)
    if motion is not None and motion.divergence is not None:
        print(f"l6470emu plot: the emulator does not reproduce {args.trace}: {divergence_text(motion)}; the picture "
              "marks it, and after it shows the emulator's model, not the capture"
              + (" (accepted: --accept-divergence)" if args.accept_divergence
                 else " (exit status 1; --accept-divergence accepts it)"), file=sys.stderr)
        if not args.accept_divergence:
            return EXIT_DIVERGED
    return 0


if __name__ == "__main__":
    sys.exit(main())
