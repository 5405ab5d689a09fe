"""Fault campaigns from Python: campaign() runs `l6470emu campaign` on a program and returns its
JSON report as a CampaignResult; campaign_merge() joins the reports of shards. The rules (points,
faults, verdicts) are the program's own, docs/campaigns.md; this module only runs and reads it."""
import json
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Dict, Iterable, Optional, Sequence, Tuple, Union

from ._paths import preload_library, program as _program

#: every verdict of a rerun, in the order the CLI counts them
VERDICTS: Tuple[str, ...] = ("detected", "survived", "silent_failure", "hang", "deadlock", "crash")
#: the verdicts that fail a campaign unless fail_on says otherwise (the CLI's default --fail-on)
DEFAULT_FAIL_ON: Tuple[str, ...] = ("silent_failure", "hang", "deadlock", "crash")
#: what fail_on may name: a verdict, or "survived-unread" (survived without reading the fault's flag)
FAIL_ON_NAMES: Tuple[str, ...] = VERDICTS + ("survived-unread",)

PathArg = Union[str, os.PathLike]
ListArg = Union[str, Iterable[Any], None]


class CampaignError(RuntimeError):
    """The campaign's clean run did not pass (`l6470emu campaign` exit status 3-7, `l6470emu run`'s
    own status for it: 3 time limit, 4 deadlock, 5 driver sanitizer, 6 the program failed, 7 no
    report), so no fault was injected. `status` is that exit status, `output` all the CLI printed."""

    def __init__(self, status: int, output: str):
        self.status: int = status
        self.output: str = output
        last = next((line for line in reversed(output.splitlines()) if line.strip()), "")
        super().__init__(f"the campaign's clean run did not pass (exit status {status}): {last}")


@dataclass(frozen=True)
class FirstFailure:
    """The first expectation a rerun failed: `where` names the user's scenario line, or "the clean
    run's end" for the clean-run oracle; `what` the register or expectation; `tick` when (250 ns
    ticks); `chip` which chip ("spidev0.0 chip 0"); `expected` and `seen` as the report writes them."""
    where: str
    what: str
    tick: int
    chip: str
    expected: str
    seen: str

    def __str__(self) -> str:
        return f"{self.what} of {self.chip} at {self.where}: expected {self.expected}, seen {self.seen}"


@dataclass(frozen=True)
class Rerun:
    """One rerun of a campaign: the program run again with `fault` raised on chip `chip` of the
    chain `chain` ("spidev0.0") at the injection point `point` ("during_motion").

    `tick` is the point's time in 250 ns ticks, `seconds` the same as the report writes it (an
    exact decimal string, "0.183351"), `after_command` the command the point follows. `verdict`
    is one of VERDICTS; `flag_read` whether the driver read STATUS after the fault rose (None for
    a fault no flag tells of); `traffic_differs` whether its SPI traffic from the point on differed
    from the clean run's; `exit` `l6470emu run`'s status for the rerun; `program` how the program
    ended ("exited with status 0"); `first_failure` a FirstFailure or None; `reproducer` the path
    of the scenario that reproduces it alone (None when none was written); `command` the
    `l6470emu run` command line that shows it again; `index` its place in the campaign's plan.
    """
    index: int
    fault: str
    chain: str
    chip: int
    point: str
    tick: int
    seconds: str
    after_command: Optional[str]
    verdict: str
    flag_read: Optional[bool]
    traffic_differs: bool
    exit: int
    program: str
    first_failure: Optional[FirstFailure]
    reproducer: Optional[str]
    command: str

    @classmethod
    def from_json(cls, j: Dict[str, Any]) -> "Rerun":
        """A Rerun from one element of the report's "reruns" array."""
        point = j["point"]
        failure = j.get("first_failure")
        return cls(index=j["index"], fault=j["fault"], chain=j["chain"], chip=j["chip"], point=point["name"],
                   tick=point["tick"], seconds=point["seconds"], after_command=point.get("after_command"),
                   verdict=j["verdict"], flag_read=j["flag_read"], traffic_differs=j["traffic_differs"],
                   exit=j["exit"], program=j["program"],
                   first_failure=None if failure is None else FirstFailure(**failure),
                   reproducer=j.get("reproducer"), command=j["command"])

    def fails(self, fail_on: ListArg = None) -> bool:
        """Whether this rerun fails the campaign by fail_on (default DEFAULT_FAIL_ON), as the CLI's
        --fail-on judges: its verdict is named, or "survived-unread" is named and it survived with
        flag_read False."""
        on = _fail_on(fail_on)
        return self.verdict in on or ("survived-unread" in on and self.verdict == "survived" and self.flag_read is False)

    def describe(self) -> str:
        """Several lines for a failure message: the verdict and where, how the program ended, the
        first failed expectation and the reproducing command."""
        lines = [f"{self.verdict}: {self.fault} on {self.chain} chip {self.chip} at {self.point} "
                 f"({self.seconds} s, after {self.after_command})",
                 f"  the program: {self.program} (run's exit {self.exit}); flag read: {self.flag_read}; "
                 f"traffic differs: {self.traffic_differs}"]
        if self.first_failure is not None:
            lines.append(f"  first failure: {self.first_failure}")
        lines.append(f"  reproduce: {self.command}")
        return "\n".join(lines)


@dataclass(frozen=True)
class CampaignResult:
    """What a campaign (or campaign_merge) gave: `status` the CLI's exit status (0 no failing
    rerun, 1 some; 128+N stopped by signal N), `reruns` a tuple of Rerun in the report's order,
    `summary` {verdict: count} for every verdict, `complete` (False when a signal stopped it),
    `total` the reruns the whole campaign plans (a shard holds only some), `output` the text the
    CLI printed (stdout and stderr as they came), `fail_on` the verdicts that fail it, `json_path`
    where the JSON report is (None when it was a temporary file, removed), `report` the whole
    JSON report as a dict. str() is the CLI's summary line."""
    status: int
    reruns: Tuple[Rerun, ...]
    summary: Dict[str, int]
    complete: bool
    total: int
    output: str = field(repr=False)
    fail_on: Tuple[str, ...] = DEFAULT_FAIL_ON
    json_path: Optional[Path] = None
    report: Dict[str, Any] = field(default_factory=dict, repr=False, compare=False)

    @property
    def failed(self) -> Tuple[Rerun, ...]:
        """The reruns that fail by fail_on (default silent_failure, hang, deadlock, crash)."""
        return tuple(r for r in self.reruns if r.fails(self.fail_on))

    @property
    def shard(self) -> Optional[str]:
        """"K/N" when this is one shard's report, else None."""
        return self.report.get("shard")

    def __str__(self) -> str:
        n = len(self.reruns)
        text = f"l6470emu campaign: {n} rerun{'' if n == 1 else 's'}"
        counts = [f"{self.summary[v]} {v}" for v in VERDICTS if self.summary.get(v)]
        if counts:
            text += ": " + ", ".join(counts)
        if not self.complete:
            text += f" (incomplete: {n} of {self.total} ran)"
        return text


def _words(value: ListArg, what: str) -> Optional[str]:
    """A sequence or comma string as the CLI's comma list; None stays None."""
    if value is None:
        return None
    if isinstance(value, (str, int)):
        text = str(value)
    else:
        text = ",".join(str(v) for v in value)
    text = text.replace(" ", "")
    if not text:
        raise ValueError(f"{what}: an empty list")
    return text


def _fail_on(value: ListArg) -> Tuple[str, ...]:
    text = _words(value, "fail_on")
    if text is None:
        return DEFAULT_FAIL_ON
    names = tuple(text.split(","))
    for name in names:
        if name not in FAIL_ON_NAMES:
            raise ValueError(f"fail_on: {name!r} is not a verdict; verdicts: {', '.join(FAIL_ON_NAMES)}")
    return names


def _environment(env: Optional[Dict[str, str]]) -> Dict[str, str]:
    out = dict(os.environ if env is None else env)
    for name in ("L6470EMU_SOCKET", "L6470EMU_CONFIG", "L6470EMU_TRACE", "L6470EMU_CHECK", "L6470EMU_CHECK_ALLOW",
                 "L6470EMU_CHAIN"):
        out.pop(name, None)  # every run's board is the campaign's, nothing inherited
    if not out.get("L6470EMU_PRELOAD"):
        try:
            out["L6470EMU_PRELOAD"] = preload_library()  # the one next to this package
        except RuntimeError:
            pass  # the program finds its own, or says it cannot
    return out


def _result(status: int, output: str, json_file: Path, fail_on: Tuple[str, ...],
            kept: Optional[Path]) -> CampaignResult:
    report = json.loads(json_file.read_text())
    if report.get("format") != "l6470emu-campaign/1":
        raise RuntimeError(f"{json_file}: not an l6470emu-campaign/1 report (format {report.get('format')!r})")
    return CampaignResult(status=status, reruns=tuple(Rerun.from_json(r) for r in report["reruns"]),
                          summary=dict(report["summary"]), complete=report["complete"], total=report["total"],
                          output=output, fail_on=fail_on, json_path=kept, report=report)


def _usage_line(output: str) -> str:
    lines = [line for line in output.splitlines() if line.strip()]
    return lines[-1] if lines else "usage error"


def _invoke(argv, cwd, env, timeout):
    done = subprocess.run(argv, cwd=cwd, env=_environment(env), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True, errors="replace", timeout=timeout)
    return done.returncode, done.stdout


def campaign(program: Sequence[PathArg], *, board: Optional[PathArg] = None, chain: Optional[str] = None,
             scenario: Optional[PathArg] = None, faults: ListArg = "all", points: str = "phases",
             chips: ListArg = None, at: ListArg = None, jobs: Optional[int] = None,
             shard: Union[str, Tuple[int, int], None] = None, fail_on: ListArg = None,
             timeout: Union[str, float, None] = None, wall_timeout: Optional[float] = None,
             json_path: Optional[PathArg] = None, junit_path: Optional[PathArg] = None,
             reproducers: Optional[str] = None, cwd: Optional[PathArg] = None,
             env: Optional[Dict[str, str]] = None) -> CampaignResult:
    """Runs `l6470emu campaign` on `program` (its argv: a sequence of str or PathLike) and returns
    its report as a CampaignResult. docs/campaigns.md is what the campaign does, docs/campaigns-python.md
    this function.

    board (a board description file) or chain (a board description text, "chips=L6470 check=warn"):
    exactly one. scenario: a scenario file whose actions happen in every rerun and whose
    expectations are the oracle. faults ("all" by default), chips, at (injection point names) and
    fail_on (verdicts; also "survived-unread") are lists: sequences or comma strings. points:
    "phases" or "every-command". jobs: reruns at once (default the CPUs). shard: "K/N" or (K, N).
    timeout: each run's simulated time limit (seconds, or "2.5s", "250ms"). wall_timeout: wall
    seconds a rerun may take before it is judged hang. reproducers: "failing" (default) or "all".
    json_path: where the JSON report goes; the reproducing scenarios are written beside it.
    Without it the report goes into a new temporary folder, removed afterwards unless a
    reproducing scenario was written there (then the commands of the failing reruns name it and
    result.json_path is the report in it). junit_path: a JUnit XML report too. cwd, env: the
    campaign's folder and environment (default the current ones, without any L6470EMU_CHAIN-like
    board settings).

    Raises ValueError for a bad argument here, or with the CLI's one line when it refuses the
    campaign (exit status 2: an unknown fault, "did you mean ...", an empty selection, ...);
    CampaignError when the clean run did not pass (status 3-7). Otherwise returns, whatever the
    verdicts: status 0 (no rerun failed by fail_on) or 1 (some did; result.failed lists them), or
    128+N when a signal stopped it (result.complete is False)."""
    if (board is None) == (chain is None):
        raise ValueError("campaign: give exactly one of board= (a board description file) and chain= (a description text)")
    argv = [os.fspath(a) for a in program]
    if not argv:
        raise ValueError("campaign: program is empty (give the program and its arguments)")
    chosen_fail_on = _fail_on(fail_on)
    cmd = [_program(), "campaign"]
    cmd += ["--board", os.fspath(board)] if board is not None else ["--chain", str(chain)]
    if scenario is not None:
        cmd += ["--scenario", os.fspath(scenario)]
    options = {"--faults": _words(faults, "faults"), "--chips": _words(chips, "chips"), "--at": _words(at, "at"),
               "--fail-on": None if fail_on is None else ",".join(chosen_fail_on)}
    for option, value in options.items():
        if value is not None:
            cmd += [option, value]
    if points is not None:
        cmd += ["--points", str(points)]
    if jobs is not None:
        cmd += ["-j", str(int(jobs))]
    if shard is not None:
        cmd += ["--shard", shard if isinstance(shard, str) else f"{shard[0]}/{shard[1]}"]
    if timeout is not None:
        cmd += ["--timeout", str(timeout)]
    if wall_timeout is not None:
        cmd += ["--wall-timeout", str(wall_timeout)]
    if junit_path is not None:
        cmd += ["--junit", os.fspath(junit_path)]
    if reproducers is not None:
        cmd += ["--reproducers", str(reproducers)]
    temporary = None
    if json_path is None:
        temporary = Path(tempfile.mkdtemp(prefix="l6470emu-campaign-"))
        json_file = temporary / "campaign.json"
    else:
        json_file = Path(json_path)
    cmd += ["--json", os.fspath(json_file), "--", *argv]
    keep = False
    try:
        status, output = _invoke(cmd, cwd, env, None)
        if status == 2:
            raise ValueError(_usage_line(output))
        if 3 <= status <= 7:
            raise CampaignError(status, output)
        if cwd is not None and not json_file.is_absolute():
            json_file = Path(cwd) / json_file
        if not json_file.exists():
            raise RuntimeError(f"l6470emu campaign exited with {status} without writing its report:\n{output}")
        result = _result(status, output, json_file, chosen_fail_on, None)
        keep = temporary is None or any(r.reproducer for r in result.reruns)
        if keep:
            result = replace(result, json_path=json_file)
        return result
    finally:
        if temporary is not None and not keep:
            shutil.rmtree(temporary, ignore_errors=True)


def campaign_merge(paths: Sequence[PathArg], output: PathArg, *, fail_on: ListArg = None) -> CampaignResult:
    """Joins the JSON reports of a campaign's shards (`l6470emu campaign merge paths... -o output`)
    into the report one unsharded run would have written, and returns it as a CampaignResult
    (status 0, or 1 when a merged rerun fails the default set). fail_on only changes what
    result.failed lists. ValueError with the CLI's line when it refuses (reports of different
    campaigns, a rerun given twice, a file that is not a report)."""
    names = [os.fspath(p) for p in paths]
    if not names:
        raise ValueError("campaign_merge: no reports given")
    status, text = _invoke([_program(), "campaign", "merge", *names, "-o", os.fspath(output)], None, None, None)
    if status == 2 or not Path(output).exists():
        raise ValueError(_usage_line(text))
    return _result(status, text, Path(output), _fail_on(fail_on), Path(output))


__all__ = ["CampaignError", "CampaignResult", "DEFAULT_FAIL_ON", "FAIL_ON_NAMES", "FirstFailure", "Rerun", "VERDICTS",
           "campaign", "campaign_merge"]
