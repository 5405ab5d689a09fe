"""Runs a Python example with every l6470emu.Chain it makes recorded into a file, for the
record-then-replay property test (tests/linux/record_replay_property_test.cpp).

    record_python_example.py memory|file OUT_DIR EXAMPLE.py [ARGS...]

memory: each Chain(record=True) records into memory as the example asks; its Chain.trace is
        saved at the end as OUT_DIR/chain-N.trace (Trace.save, the native format).
file:   each Chain(record=True) records straight into OUT_DIR/chain-N.trace instead (record=PATH,
        the recorder that writes event by event); Chain.trace reads that file back, so an example
        that looks at its own trace (motion(chain.trace)) runs unchanged.

N counts the chains in the order the example made them. Exits with the example's status; a chain
made without recording is named on stderr and makes the status 3.
"""
import runpy
import sys
from pathlib import Path

import l6470emu

mode, out_dir, example, *args = sys.argv[1:]
if mode not in ("memory", "file"):
    sys.exit(f"record_python_example.py: mode must be memory or file, not {mode!r}")
out = Path(out_dir)
made = []
_Chain = l6470emu.Chain


class RecordedChain(_Chain):
    """l6470emu.Chain, remembered, and in file mode recording into OUT_DIR."""

    def __init__(self, *a, **kw):
        self._file = None
        if mode == "file" and kw.get("record") is True:
            self._file = out / f"chain-{len(made)}.trace"
            kw["record"] = str(self._file)
        _Chain.__init__(self, *a, **kw)
        made.append(self)

    if mode == "file":
        @property
        def trace(self):
            return l6470emu.Trace.load(self._file) if self._file is not None else None


l6470emu.Chain = RecordedChain
sys.argv = [example, *args]
status = 0
try:
    runpy.run_path(example, run_name="__main__")
except SystemExit as e:
    status = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    if not isinstance(e.code, (int, type(None))):
        print(e.code, file=sys.stderr)
finally:
    for n, chain in enumerate(made):
        if mode == "memory":
            trace = chain.trace
            if trace is None:
                print(f"record_python_example.py: chain {n} was made without record=True", file=sys.stderr)
                status = status or 3
            else:
                trace.save(str(out / f"chain-{n}.trace"))
        else:
            if chain._file is None:
                print(f"record_python_example.py: chain {n} was made without record=True", file=sys.stderr)
                status = status or 3
            else:
                chain.close()
    print(f"chains={len(made)}")
sys.exit(status)
