"""Where the preload library and the l6470emu program are: $L6470EMU_PRELOAD /
$L6470EMU_PROGRAM when set, else next to this package in a build tree (_build_paths, written
by CMake), else where `cmake --install` put them (_install_paths, written at install time)."""
import os
from pathlib import Path

_HERE = Path(__file__).resolve().parent


def _locations():
    try:
        from . import _build_paths as found  # a build tree
        return Path(found.PRELOAD), Path(found.PROGRAM)
    except ImportError:
        pass
    try:
        from . import _install_paths as found  # an installed package
        return (_HERE / found.PRELOAD).resolve(), (_HERE / found.PROGRAM).resolve()
    except ImportError:
        return None, None


def _find(variable: str, default, what: str) -> str:
    given = os.environ.get(variable)
    if given:
        if not os.path.isfile(given):
            raise RuntimeError(f"{variable}={given}: no such file")
        return given
    if default is not None and default.is_file():
        return str(default)
    raise RuntimeError(
        f"{what} not found (looked for {default if default is not None else 'a build or install location'}); "
        f"build it (cmake --build build) or set {variable}")


def preload_library() -> str:
    """The path of libl6470emu-preload.so, the LD_PRELOAD library that gives unmodified
    programs emulated /dev/spidevB.C and /dev/gpiochipN nodes. RuntimeError when missing."""
    return _find("L6470EMU_PRELOAD", _locations()[0], "libl6470emu-preload.so")


def program() -> str:
    """The path of the l6470emu program. RuntimeError when missing."""
    return _find("L6470EMU_PROGRAM", _locations()[1], "the l6470emu program")
