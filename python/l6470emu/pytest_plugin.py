"""pytest plugin for testing host code against emulated L6470-family chips.

Fixtures:
  l6470_chain    an l6470emu.Chain in virtual time (in-process, no OS involved)
  l6470_board    an l6470emu.Board in virtual time in the test process: board.SpiDev / board.spidev(bus, cs)
                 behave as spidev.SpiDev, board.gpiochip(0) as a libgpiod chip; time.sleep/monotonic of
                 the code under test are the board's (options: the l6470_board marker)
  spidev_board   runs a program (your unmodified driver) under libl6470emu-preload.so with an
                 emulated /dev/spidevB.C and /dev/gpiochipN, recording a native trace
  l6470emu_campaign_case  the test's l6470emu_campaign case (fault, chip, point), or None

The chips come from the l6470_chain marker, chip 0 (the MISO end) first; default one L6470:
  @pytest.mark.l6470_chain("L6470", "2xL6480")
l6470_board's options come from its marker (all optional):
  @pytest.mark.l6470_board(bus=0, cs=0, options="speed=1000000 axis.0=...", description=None,
                           patch_time=True, record=True)

Both fixtures run the driver sanitizer at check="error": the first broken rule of the chip's
interface (SPI mode, frame length, an unknown or refused command, an answer never read, ...)
fails the test with the sanitizer's report (l6470emu.SanitizerError in process; exit status
l6470emu.SANITIZER_EXIT_STATUS under the preload). The marker's keywords change that:
  @pytest.mark.l6470_chain("L6470", check="warn", check_allow=["FRAME_LENGTH"])

A fault campaign per test (docs/campaigns-python.md): a test that runs its program with
spidev_board.run() and carries the l6470emu_campaign marker becomes one case per (fault, chip,
injection point), e.g. test_move[ocd-chip0-during_motion]; in each, run() runs the program
plainly, then `l6470emu campaign` for that one rerun, and the case fails when the rerun's verdict
is one of fail_on (default silent_failure, hang, deadlock, crash) and is skipped when the clean
run has no such point:
  @pytest.mark.l6470emu_campaign(faults=("ocd", "uvlo"), points=("during_motion",), chips=(0,),
                                 fail_on=None)

Interface coverage (docs/coverage-python.md): with --l6470emu-coverage=FILE, every Board and
Chain the session makes (the fixtures' and the tests' own) collects interface coverage into FILE,
and every program run gets L6470EMU_COVERAGE=FILE (the preload merges into it at exit). Under
pytest-xdist every worker merges into the same FILE; the session ends with a one-paragraph
summary (points met of points there are; `l6470emu coverage report FILE --show-missing` for the rest).

Installed, the plugin is registered through its pytest11 entry point; from a build tree, put
`pytest_plugins = ["l6470emu.pytest_plugin"]` in the top conftest.py (with the build's python/
directory on PYTHONPATH).
"""
import os
import subprocess
import sys
from pathlib import Path
from typing import Dict, List, NamedTuple, Optional, Sequence, Tuple, Union

import pytest

_MARKER = "l6470_chain"
_BOARD_MARKER = "l6470_board"
_BOARD_OPTIONS = ("bus", "cs", "options", "description", "patch_time", "record")
_DEFAULT_CHIPS = ("L6470",)
_CAMPAIGN_MARKER = "l6470emu_campaign"
_CAMPAIGN_OPTIONS = ("faults", "points", "chips", "fail_on")
#: the l6470emu_campaign marker's default faults: the ones every L6470, L6480, L6482 and
#: powerSTEP01 can have (name faults= for an L6472, which has no stall detection: no stall_a)
DEFAULT_CAMPAIGN_FAULTS: Tuple[str, ...] = ("ocd", "thermal_warning", "thermal_bridge_shutdown", "uvlo", "stall_a",
                                            "sw_close", "stby_pulse")
#: the l6470emu_campaign marker's default injection points: one per phase of a driver's traffic
DEFAULT_CAMPAIGN_POINTS: Tuple[str, ...] = ("after_config", "during_motion", "idle_polling", "before_last_command")
#: the l6470emu_campaign marker's default chips: chip 0 (the MISO end)
DEFAULT_CAMPAIGN_CHIPS: Tuple[int, ...] = (0,)
#: the environment variable naming the coverage file Boards, Chains and preloaded programs merge into
COVERAGE_ENV = "L6470EMU_COVERAGE"
_COVERAGE_OPTION = "--l6470emu-coverage"
# The session's coverage file (absolute) while --l6470emu-coverage is in force, else None.
_session_coverage: Optional[str] = None


class CampaignCase(NamedTuple):
    """One case of a test carrying the l6470emu_campaign marker: the fault raised, on which chip,
    at which injection point of the clean run. Its id is "FAULT-chipN-POINT"."""
    fault: str
    chip: int
    point: str

    @property
    def id(self) -> str:
        """The case's part of the test id: "ocd-chip0-during_motion"."""
        return f"{self.fault}-chip{self.chip}-{self.point}"


def pytest_addoption(parser):
    group = parser.getgroup("l6470emu", "l6470emu: emulated L6470-family chips")
    group.addoption(_COVERAGE_OPTION, dest="l6470emu_coverage", metavar="FILE", default=None,
                    help="collect the interface coverage of every l6470emu Board, Chain and program the session "
                         "runs and merge it into FILE (docs/coverage-python.md)")


def _start_coverage(config) -> None:
    """--l6470emu-coverage: FILE made absolute and checked at start-up (a usage error, not a failure at
    the end), then named in this process's environment so that every Board and Chain (coverage=None)
    and every program run collects into it. Workers take the controller's FILE (they may chdir)."""
    global _session_coverage
    workerinput = getattr(config, "workerinput", None)
    path = workerinput.get("l6470emu_coverage") if workerinput is not None else None
    if path is None:
        path = config.getoption("l6470emu_coverage", None)
        if path is None:
            return
        if not path:
            raise pytest.UsageError(f"{_COVERAGE_OPTION}: the coverage file name is empty")
        path = os.path.abspath(os.path.expanduser(path))
        from ._l6470emu import _coverage_problem

        why = _coverage_problem(path)
        if why:
            raise pytest.UsageError(f"{_COVERAGE_OPTION}: {why}")
    previous = os.environ.get(COVERAGE_ENV)
    os.environ[COVERAGE_ENV] = path
    _session_coverage = path

    def restore():
        global _session_coverage
        _session_coverage = None
        if previous is None:
            os.environ.pop(COVERAGE_ENV, None)
        else:
            os.environ[COVERAGE_ENV] = previous

    config.add_cleanup(restore)


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    """pytest-xdist: each worker gets the controller's absolute coverage file."""
    if _session_coverage is not None:
        node.workerinput["l6470emu_coverage"] = _session_coverage


def pytest_sessionfinish(session):
    """Every Board and Chain still alive merges its coverage now (a worker may end without the
    interpreter's exit handlers), before the controller's summary reads the file."""
    extension = sys.modules.get("l6470emu._l6470emu")  # a session that never imported it has nothing to merge
    if extension is None:
        return
    for why in extension._flush_coverage():
        sys.stderr.write(f"l6470emu: coverage not written: {why}\n")


def pytest_terminal_summary(terminalreporter, config):
    """The controller's one paragraph: the points met of the points there are, and the file."""
    if _session_coverage is None or hasattr(config, "workerinput"):
        return
    from ._l6470emu import coverage_total

    terminalreporter.write_sep("-", "l6470emu interface coverage")
    if not os.path.exists(_session_coverage):
        terminalreporter.write_line(f"no Board, Chain or program collected coverage: {_session_coverage} not written")
        return
    try:
        hit, total = coverage_total(_session_coverage)
    except ValueError as e:
        terminalreporter.write_line(f"cannot read the coverage: {e}")
        return
    percent = 100.0 * hit / total if total else 100.0
    terminalreporter.write_line(
        f"{hit}/{total} interface points met ({percent:.1f}%), merged into {_session_coverage}; "
        f"`l6470emu coverage report {_session_coverage} --show-missing` lists the points never met.")


def pytest_configure(config):
    _start_coverage(config)
    config.addinivalue_line(
        "markers",
        f"{_MARKER}(*chips, check=\"error\", check_allow=()): the chips of the l6470_chain and spidev_board "
        "fixtures, chip 0 (the MISO end) first, e.g. \"L6470\", \"2xL6480\" (default: one L6470), and the "
        "driver sanitizer's level and allowed rules")
    config.addinivalue_line(
        "markers",
        f"{_BOARD_MARKER}(bus=0, cs=0, options='', description=None, patch_time=True, record=True): "
        "how the l6470_board fixture builds its board")
    config.addinivalue_line(
        "markers",
        f"{_CAMPAIGN_MARKER}(faults={DEFAULT_CAMPAIGN_FAULTS!r}, points={DEFAULT_CAMPAIGN_POINTS!r}, chips=(0,), "
        "fail_on=None): a fault campaign of a spidev_board test: one case per (fault, chip, point), in which "
        "spidev_board.run() also reruns the program with that fault at that point and fails the case on a verdict "
        "of fail_on (default silent_failure, hang, deadlock, crash); docs/campaigns-python.md")


def _names(value, what: str) -> Tuple:
    """A marker keyword's list: a sequence, or a comma string."""
    if isinstance(value, (str, int)):
        value = [v.strip() for v in str(value).split(",")] if isinstance(value, str) else [value]
    try:
        names = tuple(value)
    except TypeError:
        raise pytest.UsageError(f"@pytest.mark.{_CAMPAIGN_MARKER}: {what} is a list, not {value!r}") from None
    if not names or any(n == "" for n in names):
        raise pytest.UsageError(f"@pytest.mark.{_CAMPAIGN_MARKER}: {what} is empty")
    return names


def _campaign_options(marker):
    """The l6470emu_campaign marker's (faults, points, chips, fail_on), defaults filled in."""
    unknown = sorted(set(marker.kwargs) - set(_CAMPAIGN_OPTIONS))
    if unknown or marker.args:
        raise pytest.UsageError(f"@pytest.mark.{_CAMPAIGN_MARKER}: unknown argument(s) {unknown or list(marker.args)}; "
                                f"the keywords are {', '.join(_CAMPAIGN_OPTIONS)}")
    faults = _names(marker.kwargs.get("faults", DEFAULT_CAMPAIGN_FAULTS), "faults")
    points = _names(marker.kwargs.get("points", DEFAULT_CAMPAIGN_POINTS), "points")
    chips = _names(marker.kwargs.get("chips", DEFAULT_CAMPAIGN_CHIPS), "chips")
    try:
        chips = tuple(int(c) for c in chips)
    except ValueError:
        raise pytest.UsageError(f"@pytest.mark.{_CAMPAIGN_MARKER}: chips are numbers (0 is the MISO end), "
                                f"not {chips!r}") from None
    fail_on = marker.kwargs.get("fail_on")
    if fail_on is not None:
        from .campaign import FAIL_ON_NAMES

        fail_on = _names(fail_on, "fail_on")
        bad = [v for v in fail_on if v not in FAIL_ON_NAMES]
        if bad:
            raise pytest.UsageError(f"@pytest.mark.{_CAMPAIGN_MARKER}: fail_on: {bad} not verdicts; "
                                    f"verdicts: {', '.join(FAIL_ON_NAMES)}")
    return faults, points, chips, fail_on


def pytest_generate_tests(metafunc):
    """A test with the l6470emu_campaign marker: one case per (fault, chip, point), through the
    l6470emu_campaign_case fixture (which spidev_board requests)."""
    marker = metafunc.definition.get_closest_marker(_CAMPAIGN_MARKER)
    if marker is None:
        return
    if "spidev_board" not in metafunc.fixturenames:
        other = [f for f in ("l6470_board", "l6470_chain") if f in metafunc.fixturenames]
        raise pytest.UsageError(
            f"{metafunc.definition.nodeid}: @pytest.mark.{_CAMPAIGN_MARKER} needs the spidev_board fixture: a campaign "
            "reruns a program under the preload library"
            + (f" ({' and '.join(other)} run the code in the test process, which a campaign cannot rerun)"
               if other else ""))
    faults, points, chips, _ = _campaign_options(marker)
    cases = [CampaignCase(f, c, p) for f in faults for c in chips for p in points]
    metafunc.parametrize("l6470emu_campaign_case", cases, ids=[c.id for c in cases], indirect=True)


def _check(request):
    """The marker's check= and check_allow= (default "error", none allowed)."""
    marker = request.node.get_closest_marker(_MARKER)
    kwargs = dict(marker.kwargs) if marker is not None else {}
    check = kwargs.pop("check", "error")
    allow = kwargs.pop("check_allow", ())
    if kwargs:
        raise pytest.UsageError(f"@pytest.mark.{_MARKER}: unknown keyword(s) {sorted(kwargs)} (check=, check_allow=)")
    if isinstance(allow, str):
        raise pytest.UsageError(f"@pytest.mark.{_MARKER}: check_allow is a list of rule names, not {allow!r}")
    return check, list(allow)


def _chips(request) -> List[str]:
    marker = request.node.get_closest_marker(_MARKER)
    if marker is None or not marker.args:
        return list(_DEFAULT_CHIPS)
    for chip in marker.args:
        if not isinstance(chip, str):
            raise pytest.UsageError(f"@pytest.mark.{_MARKER}: chips are strings (\"L6470\", \"2xL6480\"), not {chip!r}")
    return list(marker.args)


@pytest.fixture
def l6470_chain(request):
    """An l6470emu.Chain of the marker's chips (default one L6470), fresh from power-up."""
    import l6470emu

    check, allow = _check(request)
    chain = l6470emu.Chain(_chips(request), check=check, check_allow=allow)
    yield chain
    chain.close()


@pytest.fixture
def l6470_board(request, tmp_path, monkeypatch):
    """An l6470emu.Board of the marker's chips in virtual time, in the test process.

    Options (keywords of @pytest.mark.l6470_board): bus, cs (the spidev node, default 0, 0),
    options (more board description words), description (a whole board description instead of
    chips/bus/cs/options), patch_time (default True: time.sleep, time.monotonic and
    time.perf_counter are the board's for the test), record (default True: a native trace in
    the test's tmp_path, read by board.trace(), decode(), replay()). The driver sanitizer runs at
    the l6470_chain marker's check= (default "error": l6470emu.SanitizerError with the report)
    unless options name check= themselves.
    """
    import l6470emu

    marker = request.node.get_closest_marker(_BOARD_MARKER)
    opts = dict(marker.kwargs) if marker is not None else {}
    unknown = sorted(set(opts) - set(_BOARD_OPTIONS))
    if unknown or (marker is not None and marker.args):
        raise pytest.UsageError(f"@pytest.mark.{_BOARD_MARKER}: unknown option(s) {unknown or list(marker.args)}; "
                                f"the options are {', '.join(_BOARD_OPTIONS)}")
    trace = tmp_path / "l6470_board.trace" if opts.get("record", True) else None
    options = opts.get("options", "")
    if "check=" not in options:  # the l6470_chain marker's check= and check_allow= (default "error")
        check, allow = _check(request)
        options = " ".join(w for w in [options, f"check={check}", "check.allow=" + ",".join(allow) if allow else ""] if w)
    board = l6470emu.Board(_chips(request), bus=opts.get("bus", 0), cs=opts.get("cs", 0),
                           options=options, description=opts.get("description"),
                           trace_path=trace)
    if opts.get("patch_time", True):
        board.patch_time(monkeypatch)
    yield board
    board.close()


class SpidevBoard:
    """An emulated board for programs run under the preload library.

    run() starts a program with LD_PRELOAD=libl6470emu-preload.so and L6470EMU_CHAIN set to
    this board: the chips on /dev/spidev{bus}.{cs} and their BUSY/FLAG/SW/STCK/STBY_RST lines
    on a gpiochip, in virtual time by default (the program's clocks and sleeps are the
    board's: fast and deterministic). Each run gets a freshly powered-up board and records
    its traffic into trace_path, which trace(), decode() and replay() read.

    In a case of the l6470emu_campaign marker (campaign_case is not None), run() also runs the
    campaign of that case: see run().
    """

    def __init__(self, chips: Sequence[str], directory: Path, check: str = "error",
                 check_allow: Sequence[str] = ()):
        self.chips: List[str] = list(chips)
        #: the driver sanitizer: "error" (a broken rule of the chip ends the program with exit status
        #: l6470emu.SANITIZER_EXIT_STATUS and fails the test with the report), "warn" (log lines) or "off"
        self.check: str = check
        #: rules the sanitizer lets pass (names as in l6470emu.check_rules())
        self.check_allow: List[str] = list(check_allow)
        #: B of /dev/spidevB.C
        self.bus: int = 0
        #: C of /dev/spidevB.C
        self.cs: int = 0
        #: "virtual" (the program's clocks are the board's) or "wall"
        self.time: str = "virtual"
        #: more board description words ("speed=1000000 mode=3"), see docs/linux.md
        self.options: str = ""
        #: the native trace each run records into (None: do not record)
        self.trace_path: Optional[Path] = directory / "spidev_board.trace"
        #: where the preload library's diagnostics go
        self.log_path: Path = directory / "spidev_board.log"
        self._directory = directory
        # The l6470emu_campaign case, set by the spidev_board fixture; read through the properties.
        self._campaign_case: Optional[CampaignCase] = None
        self._campaign_fail_on: Optional[Tuple[str, ...]] = None
        self._campaign_result = None
        self._campaign_rerun = None

    @property
    def campaign_case(self) -> Optional[CampaignCase]:
        """The l6470emu_campaign case this test is, a CampaignCase (fault, chip, point), or None."""
        return self._campaign_case

    @property
    def campaign_fail_on(self) -> Optional[Tuple[str, ...]]:
        """The verdicts that fail this campaign case, from the marker's fail_on (None: the default
        silent_failure, hang, deadlock, crash)."""
        return self._campaign_fail_on

    @property
    def campaign_json_path(self) -> Path:
        """Where a campaign case's JSON report goes (its reproducing scenario is written beside it,
        in the test's tmp_path)."""
        return self._directory / "spidev_board.campaign.json"

    @property
    def campaign_result(self):
        """The last run()'s l6470emu.CampaignResult in a campaign case, else None."""
        return self._campaign_result

    @property
    def campaign_rerun(self):
        """The last run()'s l6470emu.Rerun in a campaign case (the case's one rerun), else None."""
        return self._campaign_rerun

    @property
    def preload(self) -> str:
        """The preload library's path (found in the build tree or the installed location)."""
        import l6470emu

        return l6470emu.preload_library()

    @property
    def description(self) -> str:
        """The board description given as L6470EMU_CHAIN."""
        words = [f"bus={self.bus}", f"cs={self.cs}", "chips=" + ",".join(self.chips), f"time={self.time}",
                 f"check={self.check}"]
        if self.check_allow:
            words.append("check.allow=" + ",".join(self.check_allow))
        if self.options:
            words.append(self.options)
        return " ".join(words)

    @property
    def device(self) -> str:
        """The spidev node the program opens."""
        return f"/dev/spidev{self.bus}.{self.cs}"

    def env(self, base: Optional[Dict[str, str]] = None) -> Dict[str, str]:
        """The environment a program runs in: `base` (default os.environ) plus the preload."""
        env = dict(os.environ if base is None else base)
        for name in ("L6470EMU_SOCKET", "L6470EMU_CONFIG", "L6470EMU_TRACE", "L6470EMU_CHECK", "L6470EMU_CHECK_ALLOW"):
            env.pop(name, None)  # this board, in process, nothing inherited
        preload = self.preload
        env["LD_PRELOAD"] = preload + (":" + env["LD_PRELOAD"] if env.get("LD_PRELOAD") else "")
        env["L6470EMU_CHAIN"] = self.description
        env["L6470EMU_LOG"] = str(self.log_path)
        if self.trace_path is not None:
            env["L6470EMU_TRACE"] = str(self.trace_path)
        if _session_coverage is not None:  # --l6470emu-coverage: the preload merges into it at exit
            env[COVERAGE_ENV] = _session_coverage
        return env

    def run(self, args: Sequence[Union[str, os.PathLike]], *, timeout: float = 60, check: bool = True,
            input: Optional[str] = None, cwd: Optional[Union[str, os.PathLike]] = None,
            env: Optional[Dict[str, str]] = None) -> subprocess.CompletedProcess:
        """Runs args under the board; returns the CompletedProcess (text stdout and stderr).

        A trace left by an earlier run is removed first. With check (the default), a
        non-zero exit fails the test with the program's output and the board's log; an exit by
        the driver sanitizer (status l6470emu.SANITIZER_EXIT_STATUS) fails it with the report.

        In an l6470emu_campaign case (campaign_case is (fault, chip, point)), the program first
        runs as above — the campaign's clean run; what run() returns, and what trace(), decode()
        and log() read, is that run's — and then `l6470emu campaign --chain DESCRIPTION --faults
        FAULT --chips CHIP --at POINT --json campaign_json_path -- args` runs (in cwd, with env; the
        rerun's wall-clock limit is timeout; input is not given to it). Its result and the rerun
        are campaign_result and campaign_rerun. The case fails (pytest.fail) when the rerun's
        verdict is one of campaign_fail_on (default silent_failure, hang, deadlock, crash), with the
        verdict, how the program ended, the first failed expectation and the command that
        reproduces it; when the campaign's clean run does not pass; and when the campaign refuses
        the marker's faults or chips. It is skipped when the clean run has no such point for that
        chip. Otherwise run() returns as usual."""
        if self.trace_path is not None and self.trace_path.exists():
            self.trace_path.unlink()
        argv = [os.fspath(a) for a in args]
        result = subprocess.run(argv, env=self.env(env), cwd=cwd, input=input, capture_output=True, text=True,
                                timeout=timeout)
        if check and result.returncode != 0:
            import l6470emu

            if result.returncode == l6470emu.SANITIZER_EXIT_STATUS:
                report = result.stderr[result.stderr.find("l6470emu: driver sanitizer:"):]
                pytest.fail(
                    f"{' '.join(argv)} broke a rule of the chip on board '{self.description}':\n{report}"
                    f"--- stdout\n{result.stdout}", pytrace=False)
            pytest.fail(
                f"{' '.join(argv)} exited with {result.returncode} on board '{self.description}'\n"
                f"--- stdout\n{result.stdout}--- stderr\n{result.stderr}--- board log\n{self.log()}",
                pytrace=False)
        if self.campaign_case is not None:
            self._campaign(argv, timeout=timeout, cwd=cwd, env=env)
        return result

    def _campaign(self, argv: List[str], *, timeout: float, cwd, env) -> None:
        """The campaign of campaign_case for argv: fails or skips the test as run() says."""
        import l6470emu

        fault, chip, point = self.campaign_case
        self._campaign_result = self._campaign_rerun = None
        try:
            if env is not None and _session_coverage is not None:
                env = dict(env, **{COVERAGE_ENV: _session_coverage})
            result = l6470emu.campaign(argv, chain=self.description, faults=fault, chips=chip, at=point,
                                       fail_on=self.campaign_fail_on, json_path=self.campaign_json_path, jobs=1,
                                       wall_timeout=timeout, cwd=cwd, env=env)
        except ValueError as refused:
            pytest.fail(f"@pytest.mark.{_CAMPAIGN_MARKER}: {refused}", pytrace=False)
        except l6470emu.CampaignError as clean:
            pytest.fail(f"{' '.join(argv)}: the campaign's clean run on board '{self.description}' did not pass "
                        f"(exit status {clean.status}); no fault was injected\n--- campaign output\n{clean.output}",
                        pytrace=False)
        self._campaign_result = result
        if not result.reruns:
            pytest.skip(f"the clean run of {' '.join(argv)} has no {point} point for chip {chip}: no {fault} rerun")
        rerun = self._campaign_rerun = result.reruns[0]
        if rerun.fails(self.campaign_fail_on):
            pytest.fail(f"{' '.join(argv)} on board '{self.description}' with {fault} on chip {chip} at {point}:\n"
                        f"{rerun.describe()}", pytrace=False)

    def python(self, script: Union[str, os.PathLike], *args: str, **kwargs) -> subprocess.CompletedProcess:
        """run() of a Python script with this interpreter (sys.executable)."""
        return self.run([sys.executable, os.fspath(script), *args], **kwargs)

    def log(self) -> str:
        """What the preload library reported (settings the chip cannot work with, host mistakes)."""
        return self.log_path.read_text(errors="replace") if self.log_path.exists() else ""

    def _recorded(self) -> Path:
        if self.trace_path is None or not self.trace_path.exists():
            raise RuntimeError("no trace recorded: run() a program first (and keep trace_path set)")
        return self.trace_path

    def trace(self):
        """The last run's trace, as an l6470emu.Trace."""
        import l6470emu

        return l6470emu.Trace.load(self._recorded())

    def decode(self, **options) -> str:
        """The last run's traffic explained, per chip (l6470emu.decode)."""
        import l6470emu

        return l6470emu.decode(self._recorded(), **options).text

    def replay(self, **options):
        """The last run's trace replayed against a fresh chain (an l6470emu.ReplayResult)."""
        import l6470emu

        return l6470emu.replay(self._recorded(), **options)


@pytest.fixture
def l6470emu_campaign_case(request) -> Optional[CampaignCase]:
    """The l6470emu_campaign case of this test, a CampaignCase (fault, chip, point), or None for a
    test without the marker (pytest_generate_tests parametrizes it)."""
    return getattr(request, "param", None)


@pytest.fixture
def spidev_board(request, tmp_path, l6470emu_campaign_case):
    """A SpidevBoard of the marker's chips (default one L6470) for running programs under the preload;
    in an l6470emu_campaign case, its campaign_case and campaign_fail_on are the case's."""
    check, allow = _check(request)
    board = SpidevBoard(_chips(request), tmp_path, check=check, check_allow=allow)
    if l6470emu_campaign_case is not None:
        board._campaign_case = l6470emu_campaign_case
        board._campaign_fail_on = _campaign_options(request.node.get_closest_marker(_CAMPAIGN_MARKER))[3]
    return board
