"""l6470emu: a register-level emulator of the ST L6470-family SPI motion engines for Python.

Chain(["L6470", "L6480"]) is a daisy chain of emulated chips in virtual time: byte-level
frames (Chain.frame), the reference host's commands (get_status, move, ...), pins and faults,
a driver sanitizer (check="error" by default: the first broken rule of the chip raises
SanitizerError with its report; check_rules() lists the rules),
STATUS decoded (Status), and recording into native traces that replay() and decode() read;
motion() samples what each chip did over a trace, and l6470emu.plot draws it (matplotlib).
Board is a board description's board in the test process: spidev.SpiDev-like devices and
libgpiod-like lines in virtual time (l6470emu.board). The pytest plugin (l6470emu.pytest_plugin)
gives tests the l6470_chain, l6470_board and spidev_board fixtures; preload_library() finds
libl6470emu-preload.so for running unmodified programs.
l6470emu.units converts register values to physical units (step/s, mA, ...) and back.
campaign() runs `l6470emu campaign` (every fault at every point of a program's run, each rerun
judged) and returns its report as a CampaignResult; campaign_merge() joins shards' reports
(docs/campaigns-python.md).
Board and Chain collect interface coverage with coverage=FILE (default: $L6470EMU_COVERAGE);
coverage_report() and coverage_total() read coverage files (docs/coverage-python.md).
"""
from ._l6470emu import (
    DEFAULT_MAX_FRAMES,
    MAX_MOTION_POINTS,
    TICKS_PER_SECOND,
    Bridge,
    Chain,
    ChipMotion,
    CommandMark,
    DecodeResult,
    Diagnostic,
    Divergence,
    Fault,
    FirstDivergence,
    Motion,
    Reg,
    RegisterInfo,
    ReplayResult,
    SANITIZER_EXIT_STATUS,
    SanitizerError,
    SanitizerWarning,
    Thermal,
    Trace,
    TraceError,
    TraceEvent,
    __version__,
    check_rules,
    coverage_report,
    coverage_total,
    decode,
    motion,
    register_table,
    replay,
    variants,
)
from ._paths import preload_library, program
from ._status import Status
from .campaign import CampaignError, CampaignResult, FirstFailure, Rerun, campaign, campaign_merge
from . import units
from .board import Board

__all__ = [
    "DEFAULT_MAX_FRAMES",
    "MAX_MOTION_POINTS",
    "TICKS_PER_SECOND",
    "Board",
    "Bridge",
    "CampaignError",
    "CampaignResult",
    "Chain",
    "ChipMotion",
    "CommandMark",
    "DecodeResult",
    "Diagnostic",
    "Divergence",
    "FirstDivergence",
    "FirstFailure",
    "Fault",
    "Reg",
    "Motion",
    "RegisterInfo",
    "Rerun",
    "ReplayResult",
    "SANITIZER_EXIT_STATUS",
    "SanitizerError",
    "SanitizerWarning",
    "Status",
    "Thermal",
    "Trace",
    "TraceError",
    "TraceEvent",
    "__version__",
    "campaign",
    "campaign_merge",
    "check_rules",
    "coverage_report",
    "coverage_total",
    "decode",
    "motion",
    "preload_library",
    "program",
    "register_table",
    "units",
    "replay",
    "variants",
]
