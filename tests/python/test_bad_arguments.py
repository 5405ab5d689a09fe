"""Every Chain method and module function, called with arguments of every wrong kind, raises
a Python exception (TypeError, ValueError, RuntimeError, IndexError): never a crash, never a
C++ exception escaping as something else."""
import inspect
import itertools

import l6470emu

ODD_VALUES = [None, -1, 2**64, 1.5, float("nan"), "", "x", b"\xff" * 3, [], [300], object(), True]
# SanitizerError: odd bytes that reach the chain break the chip's rules (check="error").
EXPECTED = (TypeError, ValueError, RuntimeError, IndexError, AttributeError, l6470emu.SanitizerError)


def call_all(method):
    """Calls `method` with 1, 2 and 3 odd arguments in many combinations."""
    for arity in (1, 2, 3):
        for args in itertools.islice(itertools.product(ODD_VALUES, repeat=arity), 200):
            try:
                method(*args)
            except EXPECTED:
                pass


def test_chain_methods_refuse_odd_arguments_with_python_exceptions(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a str argument may be taken as a file name
    for name, member in inspect.getmembers(l6470emu.Chain):
        if name.startswith("_") or not callable(member):
            continue
        chain = l6470emu.Chain(["L6470", "L6480"], record=True)
        call_all(getattr(chain, name))
        assert l6470emu.replay(chain.trace).matched  # whatever got through was recorded faithfully


def test_module_functions_refuse_odd_arguments_with_python_exceptions(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name in ("replay", "decode", "register_table"):
        call_all(getattr(l6470emu, name))
    for args in itertools.product(ODD_VALUES, repeat=1):
        for make in (lambda a: l6470emu.Chain(a), lambda a: l6470emu.Chain(record=a), l6470emu.Trace.load,
                     l6470emu.Trace.parse, lambda a: l6470emu.Chain(frame_gap_ticks=a),
                     lambda a: l6470emu.Chain(coverage=a), lambda a: l6470emu.Board(coverage=a),
                     l6470emu.coverage_report, l6470emu.coverage_total):
            try:
                make(*args)
            except EXPECTED:
                pass
