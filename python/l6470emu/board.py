"""An emulated board inside the test process: a driver class gets a spidev.SpiDev-like device
and libgpiod-like lines (python3-libgpiod 1.x API), all in virtual time.

    board = l6470emu.Board("L6470")
    spi = board.spidev(0, 0)            # behaves as spidev.SpiDev() opened on /dev/spidev0.0
    busy = board.gpiochip(0).find_line("BUSY")
    busy.request(consumer="test", type=l6470emu.board.LINE_REQ_EV_BOTH_EDGES)
    spi.xfer2([0x50, 0x00, 0x32, 0x00])   # Run
    busy.event_wait(sec=1)              # virtual time runs to BUSY's edge (or 1 s), at once

Time moves only when something takes time: an SPI message takes its bus time, a wait runs the
board to the edge it waits for (or its timeout), sleep()/advance() move it. patch_time() makes
time.sleep/time.monotonic/time.perf_counter of the code under test the board's time too.
The spidev device rules (settings, validation, chip-select timing, word and bit order) are the
ones the preload library applies to programs (linux/spidev_rules.hpp), so a driver behaves here
as it does under spidev_board, byte for byte and tick for tick.
"""
import errno
import os
import time as _time
from typing import Iterable, List, Optional, Sequence, Union

from ._l6470emu import TICKS_PER_SECOND, _BoardCore

__all__ = ["Board", "SpiDev", "GpioChip", "Line", "LineBulk", "LineEvent",
           "LINE_REQ_DIR_AS_IS", "LINE_REQ_DIR_IN", "LINE_REQ_DIR_OUT", "LINE_REQ_EV_FALLING_EDGE",
           "LINE_REQ_EV_RISING_EDGE", "LINE_REQ_EV_BOTH_EDGES", "LINE_REQ_FLAG_ACTIVE_LOW", "PINS"]

# python3-libgpiod 1.x's request types and flags (the same numbers, so gpiod's constants work too).
LINE_REQ_DIR_AS_IS = 1
LINE_REQ_DIR_IN = 2
LINE_REQ_DIR_OUT = 3
LINE_REQ_EV_FALLING_EDGE = 4
LINE_REQ_EV_RISING_EDGE = 5
LINE_REQ_EV_BOTH_EDGES = 6
LINE_REQ_FLAG_OPEN_DRAIN = 1
LINE_REQ_FLAG_OPEN_SOURCE = 2
LINE_REQ_FLAG_ACTIVE_LOW = 4

#: The pins of each chip, in gpiochip line order: offset = 5 * chip + index for the first five;
#: DIR (an L6474's) on a chain with one, offset = 5 * chips + chip.
PINS = ("BUSY", "FLAG", "SW", "STCK", "STBY_RST", "DIR")

#: Where the host's CLOCK_MONOTONIC stands at tick 0 (as under the preload in virtual time), ns.
MONOTONIC_ORIGIN_NS = 1_000_000_000_000
_NS_PER_TICK = 1_000_000_000 // TICKS_PER_SECOND

# spidev mode bits (linux/spi/spi.h)
_SPI_CPHA, _SPI_CPOL, _SPI_CS_HIGH, _SPI_LSB_FIRST = 0x01, 0x02, 0x04, 0x08
_SPI_3WIRE, _SPI_LOOP, _SPI_NO_CS = 0x10, 0x20, 0x40


def _pin_index(pin: Union[str, int]) -> int:
    if isinstance(pin, int) and 0 <= pin < len(PINS):
        return pin
    if isinstance(pin, str) and pin.upper() in PINS:
        return PINS.index(pin.upper())
    raise ValueError(f"pin {pin!r}: one of {', '.join(PINS)}")


def _chips_word(chips) -> str:
    if isinstance(chips, int):
        return f"{chips}xL6470"
    if isinstance(chips, str):
        return chips
    return ",".join(chips)


class Board:
    """The chains of a board description in virtual time, in this process.

    chips: the chips of one chain, chip 0 (the MISO end) first ("L6470", "2xL6480", a list, or a
    number of L6470s), on /dev/spidev{bus}.{cs} with its pins on a gpiochip; options: more board
    description words ("speed=1000000 mode=3 axis.0=..."). description: a whole board
    description instead (several chains separated by ';', docs/linux.md). trace_path: record
    every chain into this native trace (trace(), decode(), replay() read it). check: the driver
    sanitizer, "error" (default: the first broken rule of the chip raises l6470emu.SanitizerError
    with the report), "warn" (an l6470emu.SanitizerWarning and a log line) or "off"; check_allow: rule names let pass. A
    description or options naming check= themselves win. coverage: collect interface coverage of
    everything the board meets and merge it into this file on close(), at the end of a `with`,
    when the board is destroyed or the interpreter exits (docs/coverage-python.md); True
    collects it in memory only (coverage_data()), False not at all; None (default) collects
    into $L6470EMU_COVERAGE when it is set. A file that cannot take coverage is a ValueError here.
    The code under test's reads count as the driver's (Line.get_value of BUSY/FLAG, the edge
    events event_read hands out); the test's own looks (level(), axis()) do not.
    """

    def __init__(self, chips: Union[str, int, Sequence[str]] = "L6470", *, bus: int = 0, cs: int = 0,
                 options: str = "", description: Optional[str] = None,
                 trace_path: Optional[Union[str, os.PathLike]] = None,
                 check: str = "error", check_allow: Sequence[str] = (),
                 coverage: Union[str, os.PathLike, bool, None] = None):
        if description is None:
            description = f"bus={bus} cs={cs} chips={_chips_word(chips)}"
            if options:
                description += " " + options
        if "time=" not in description:
            description += " time=virtual"
        if "check=" not in description:
            if isinstance(check_allow, str):
                raise TypeError(f"check_allow is a sequence of rule names, not {check_allow!r}")
            description += f" check={check}" + (" check.allow=" + ",".join(check_allow) if check_allow else "")
        #: the board description the board was built from
        self.description: str = description
        self._core = _BoardCore(description, "l6470emu.Board", coverage)
        self.trace_path = None if trace_path is None else os.fspath(trace_path)
        self._log: List[str] = []
        self._gpiochips = {}
        if self.trace_path is not None:
            self._core.start_recording_all(self.trace_path)

    # ---- devices -------------------------------------------------------------------

    def spidev(self, bus: Optional[int] = None, cs: Optional[int] = None) -> "SpiDev":
        """A spidev.SpiDev work-alike on this board, opened on /dev/spidev{bus}.{cs} when both are given."""
        return SpiDev(bus, cs, board=self)

    def SpiDev(self, bus: Optional[int] = None, device: Optional[int] = None) -> "SpiDev":
        """spidev.SpiDev's constructor on this board: monkeypatch.setattr(spidev, "SpiDev", board.SpiDev)."""
        return SpiDev(bus, device, board=self)

    def gpiochip(self, chip: Union[int, str] = 0) -> "GpioChip":
        """The gpiochip carrying a chain's pins, by chain index, /dev/gpiochipN, "gpiochipN" or N as a string."""
        if isinstance(chip, int) and 0 <= chip < self._core.chain_count():
            found = chip
        else:
            found = self._find_gpiochip(chip)
        if found not in self._gpiochips:
            self._gpiochips[found] = GpioChip(self, found)
        return self._gpiochips[found]

    def _find_gpiochip(self, chip) -> int:
        found = self._core.find_chain(os.path.basename(str(chip)))
        if found < 0 and str(chip).isdigit():
            found = self._core.find_chain(f"gpiochip{chip}")
        if found < 0:
            raise FileNotFoundError(errno.ENOENT, "no such gpiochip on the board", str(chip))
        return found

    def line(self, chip: int = 0, pin: Union[str, int] = "BUSY", *, chain: int = 0) -> "Line":
        """Pin `pin` of chip `chip` of chain `chain` as a libgpiod line (not yet requested)."""
        gpiochip = self.gpiochip(chain)
        return gpiochip.get_line(gpiochip._offset(chip, _pin_index(pin)))

    def chain_count(self) -> int:
        return self._core.chain_count()

    def chips(self, chain: int = 0) -> List[str]:
        """The variants of chain `chain`, chip 0 first."""
        return self._core.variants(chain)

    # ---- time ----------------------------------------------------------------------

    @property
    def tick(self) -> int:
        """The board's time in 250 ns ticks."""
        return self._core.now()

    @property
    def seconds(self) -> float:
        """The board's time in seconds since power-up."""
        return self._core.now() / TICKS_PER_SECOND

    def monotonic_ns(self) -> int:
        """CLOCK_MONOTONIC as the code under test sees it (time.monotonic_ns under patch_time)."""
        return MONOTONIC_ORIGIN_NS + self._core.now() * _NS_PER_TICK

    def monotonic(self) -> float:
        return self.monotonic_ns() / 1e9

    def advance(self, seconds: float = 0.0, *, ticks: int = 0) -> None:
        """Lets `seconds` (plus `ticks`) of virtual time pass; edges happen on the way."""
        if seconds < 0 or ticks < 0:
            raise ValueError("time only moves forward")
        self._core.advance_to(self._core.now() + int(round(seconds * TICKS_PER_SECOND)) + ticks)

    def advance_to(self, tick: int) -> None:
        """Moves the board's time to `tick` (never backwards)."""
        self._core.advance_to(tick)

    sleep = advance

    def patch_time(self, monkeypatch) -> None:
        """Makes time.sleep, time.monotonic(_ns) and time.perf_counter(_ns) the board's time for
        the rest of the test (through pytest's monkeypatch; undone at its end). Code that did
        `from time import sleep` at import keeps the real one."""
        monkeypatch.setattr(_time, "sleep", self.advance)
        monkeypatch.setattr(_time, "monotonic", self.monotonic)
        monkeypatch.setattr(_time, "monotonic_ns", self.monotonic_ns)
        monkeypatch.setattr(_time, "perf_counter", self.monotonic)
        monkeypatch.setattr(_time, "perf_counter_ns", self.monotonic_ns)

    # ---- the physical world ------------------------------------------------------

    def level(self, chip: int = 0, pin: Union[str, int] = "BUSY", *, chain: int = 0) -> int:
        """The physical level (0/1) of a pin now: BUSY and FLAG are low when active."""
        return int(self._core.level(chain, chip, _pin_index(pin)))

    def drive(self, chip: int, pin: Union[str, int], level: int, *, chain: int = 0) -> None:
        """Drives an input pin (SW, STCK, STBY_RST; DIR on an L6474) as the physical world would."""
        self._core.drive(chain, chip, _pin_index(pin), bool(level))

    def fault(self, chip: int, fault, value: Optional[int] = None, *, chain: int = 0) -> None:
        """A backdoor event: UVLO, UVLO_ADC, OCD, STALL_A, STALL_B 0/1 (default 1), THERMAL 0..3,
        ADCIN 0..31; the one-shot POWER_CYCLE (a brown-out) and LOST_FRAME (the chip misses the
        next CS frame) take no value, MISO_FLIP the bit 0..7 (default 7) inverted in the chip's
        MISO byte of the next frame."""
        self._core.fault(chain, chip, fault, -1 if value is None else value)

    def attach_axis(self, chip: int = 0, spec: str = "default", *, chain: int = 0) -> None:
        """Puts a motor, load, stops and switches behind chip `chip`: the board description's
        axis items ("steps=200,load=120,stops=-2000..90000,switch=home@0"; docs/linux.md).
        Positions are 1/128 step. From now on the axis drives SW, stall and overcurrent."""
        self._core.attach_axis(chain, chip, "" if spec == "default" else spec)

    def axis(self, chip: int = 0, *, chain: int = 0) -> dict:
        """The axis now: position (true, 1/128 step), lost_steps, synchronised, at_stop,
        switches (name: actuated), sw_level, stall, overcurrent, phase_current_mA, spec."""
        return self._core.axis(chain, chip)

    def set_load(self, chip: int = 0, load: str = "", *, chain: int = 0) -> None:
        """Changes the axis's load now: "load=G_CM2,friction=NM,force=NM"."""
        self._core.set_load(chain, chip, load)

    # ---- diagnostics and the recording ---------------------------------------------

    def log(self) -> str:
        """What the board reported so far (settings the chip cannot work with, host mistakes)."""
        lines, dropped = self._core.take_log()
        self._log.extend(lines)
        if dropped:
            self._log.append(f"({dropped} lines not kept)")
        return "".join(line + "\n" for line in self._log)

    def close(self) -> None:
        """Stops recording (the trace file is complete) and merges the interface coverage met so
        far into the coverage file (RuntimeError when it cannot be written); the board stays usable."""
        for k in range(self._core.chain_count()):
            self._core.stop_recording(k)
        self._core.flush_coverage()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # ---- interface coverage ----------------------------------------------------------

    def coverage_data(self) -> Optional[dict]:
        """The interface coverage met so far as a dict, the coverage file's structure
        ({"format", "version", "variants": {VARIANT: {"hit": {CATEGORY: [POINT, ...]},
        "chain positions present": [...]}}}), or None when the board collects none."""
        return self._core.coverage_data()

    @property
    def coverage_path(self) -> Optional[str]:
        """The coverage file the board merges into (absolute), or None."""
        return self._core.coverage_path()

    def _recorded(self) -> str:
        if self.trace_path is None:
            raise RuntimeError("this board records no trace (give trace_path)")
        self.close()
        return self.trace_path

    def trace(self):
        """The recording so far, as an l6470emu.Trace (recording stops)."""
        from ._l6470emu import Trace
        return Trace.load(self._recorded())

    def decode(self, **options) -> str:
        """The traffic so far explained, per chip (l6470emu.decode; recording stops)."""
        from ._l6470emu import decode
        return decode(self._recorded(), **options).text

    def replay(self, **options):
        """The recording replayed against a fresh chain (l6470emu.replay; recording stops)."""
        from ._l6470emu import replay
        return replay(self._recorded(), **options)


# ---------------------------------------------------------------------------- spidev

def _ints(values, what: str) -> bytes:
    try:
        return bytes(values)
    except (TypeError, ValueError):
        raise TypeError(f"{what}: a sequence of ints 0..255 is needed") from None


class SpiDev:
    """spidev.SpiDev (py-spidev 3.x) on an emulated board: open, close, mode, max_speed_hz,
    bits_per_word, lsbfirst, cshigh, threewire, loop, no_cs, xfer, xfer2, xfer3, readbytes,
    writebytes, writebytes2, and `with`. Each call is the system call py-spidev makes, with the
    kernel's rules and errors (OSError with errno); the mode is kept in the device's settings
    and handed to the board with every message."""

    def __init__(self, bus: Optional[int] = None, device: Optional[int] = None, *, board: Board):
        self._board = board
        self._chain: Optional[int] = None
        self._mode32 = 0
        self._bits = 0
        self._speed = 0
        self._bufsiz = 4096
        #: stored only (py-spidev's read0: a 0-byte read after a transfer with cshigh)
        self.read0 = False
        if bus is not None:
            self.open(bus, device)

    # open / close
    def open(self, bus: int, device: int) -> None:
        if self._chain is not None:
            self.close()
        chain = self._board._core.find_chain(f"{bus}.{device}")
        if chain < 0:
            raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), f"/dev/spidev{bus}.{device}")
        self._board._core.spi_open(chain)
        self._chain = chain
        mode32, bits, speed, self._bufsiz = self._board._core.spi_settings(chain)
        self._mode32, self._bits, self._speed = mode32 & 0xFF, bits, speed

    def close(self) -> None:
        if self._chain is not None:
            self._board._core.spi_close(self._chain)
        self._chain = None
        self._mode32 = self._bits = self._speed = 0

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def _open_chain(self) -> int:
        if self._chain is None:
            raise OSError(errno.EBADF, os.strerror(errno.EBADF))
        return self._chain

    def _set_mode_bits(self, mask: int, on: bool) -> None:
        chain = self._open_chain()
        mode32 = (self._mode32 | mask) if on else (self._mode32 & ~mask)
        self._board._core.spi_ioctl(chain, "mode32", mode32)
        self._mode32 = mode32

    # settings
    @property
    def mode(self) -> int:
        return self._mode32 & (_SPI_CPHA | _SPI_CPOL)

    @mode.setter
    def mode(self, value: int) -> None:
        if not isinstance(value, int) or value != (value & 3):
            raise TypeError("The mode attribute must be an integer between 0 and 3.")
        chain = self._open_chain()
        mode32 = (self._mode32 & ~3) | value
        self._board._core.spi_ioctl(chain, "mode32", mode32)
        self._mode32 = mode32

    def _flag(mask):  # noqa: N805 - property factory
        return property(lambda self: bool(self._mode32 & mask),
                        lambda self, on: self._set_mode_bits(mask, bool(on)))

    cshigh = _flag(_SPI_CS_HIGH)
    lsbfirst = _flag(_SPI_LSB_FIRST)
    threewire = _flag(_SPI_3WIRE)
    loop = _flag(_SPI_LOOP)
    no_cs = _flag(_SPI_NO_CS)
    del _flag

    @property
    def bits_per_word(self) -> int:
        return self._bits

    @bits_per_word.setter
    def bits_per_word(self, value: int) -> None:
        if not isinstance(value, int) or not 8 <= value <= 16:
            raise TypeError("The bits_per_word attribute must be an integer between 8 and 16.")
        self._board._core.spi_ioctl(self._open_chain(), "bits_per_word", value)
        self._bits = value

    @property
    def max_speed_hz(self) -> int:
        return self._speed

    @max_speed_hz.setter
    def max_speed_hz(self, value: int) -> None:
        if not isinstance(value, int) or value < 0:
            raise TypeError("The max_speed_hz attribute must be an integer")
        self._board._core.spi_ioctl(self._open_chain(), "max_speed_hz", value)
        self._speed = value

    # transfers
    def _message(self, transfers) -> bytes:
        return self._board._core.spi_message(self._open_chain(), transfers)

    def _xfer(self, values, speed_hz: int, delay_usecs: int, bits_per_word: int) -> bytes:
        tx = _ints(values, "xfer")
        if len(tx) > self._bufsiz:
            raise OverflowError(f"Argument list size exceeds {self._bufsiz} bytes.")
        return self._message([(tx, True, len(tx), speed_hz or self._speed, delay_usecs,
                               bits_per_word or self._bits, False, 0)])

    def xfer(self, values, speed_hz: int = 0, delay_usecs: int = 0, bits_per_word: int = 0) -> List[int]:
        """One transfer of `values` under one chip select; the bytes read back."""
        return list(self._xfer(values, speed_hz, delay_usecs, bits_per_word))

    def xfer2(self, values, speed_hz: int = 0, delay_usecs: int = 0, bits_per_word: int = 0) -> List[int]:
        """As xfer (py-spidev 3.x builds both as one transfer, CS held for the whole list)."""
        return list(self._xfer(values, speed_hz, delay_usecs, bits_per_word))

    def xfer3(self, values, speed_hz: int = 0, delay_usecs: int = 0, bits_per_word: int = 0) -> tuple:
        """As xfer2 for lists of any length: one message per bufsiz bytes (CS rises between them)."""
        tx = _ints(values, "xfer3")
        out = bytearray()
        for at in range(0, len(tx), self._bufsiz):
            out += self._xfer(tx[at:at + self._bufsiz], speed_hz, delay_usecs, bits_per_word)
        return tuple(out)

    def readbytes(self, length: int) -> List[int]:
        """read(): `length` bytes clocked in while zeros go out."""
        if length > self._bufsiz:
            raise OSError(errno.EMSGSIZE, os.strerror(errno.EMSGSIZE))
        return list(self._message([(None, True, length, 0, 0, 0, False, 0)]))

    def writebytes(self, values) -> None:
        """write(): the bytes out, nothing read."""
        tx = _ints(values, "writebytes")
        if len(tx) > self._bufsiz:
            raise OverflowError(f"Argument list size exceeds {self._bufsiz} bytes.")
        self._message([(tx, False, len(tx), 0, 0, 0, False, 0)])

    def writebytes2(self, values) -> None:
        """write() of any length and of buffers (bytes, bytearray, numpy), bufsiz bytes per call."""
        tx = bytes(memoryview(values).cast("B")) if not isinstance(values, (list, tuple)) else _ints(values, "writebytes2")
        for at in range(0, len(tx), self._bufsiz):
            chunk = tx[at:at + self._bufsiz]
            self._message([(chunk, False, len(chunk), 0, 0, 0, False, 0)])

    def __repr__(self):
        where = "closed" if self._chain is None else self._board._core.chain_name(self._chain)
        return f"<l6470emu SpiDev {where}>"


# ---------------------------------------------------------------------------- gpiod

class LineEvent:
    """An edge of a requested line, as gpiod.LineEvent: type, sec, nsec (CLOCK_MONOTONIC of the board), source."""
    RISING_EDGE = 1
    FALLING_EDGE = 2

    def __init__(self, type: int, tick: int, source: "Line"):
        self.type = type
        ns = MONOTONIC_ORIGIN_NS + tick * _NS_PER_TICK
        self.sec, self.nsec = divmod(ns, 1_000_000_000)
        #: the board's tick of the edge
        self.tick = tick
        self.source = source

    def __repr__(self):
        kind = "RISING_EDGE" if self.type == self.RISING_EDGE else "FALLING_EDGE"
        return f"LineEvent({kind}, {self.source.name()}, tick {self.tick})"


class Line:
    """A line of an emulated gpiochip with python3-libgpiod 1.x's Line API: request, release,
    get_value, set_value, event_wait, event_read, event_read_multiple. Waiting runs the board's
    virtual time to the next edge (or to the timeout) at once."""
    DIRECTION_INPUT = 1
    DIRECTION_OUTPUT = 2

    def __init__(self, chip: "GpioChip", offset: int):
        self._chip = chip
        self._offset = offset
        self._type: Optional[int] = None
        self._flags = 0
        self._consumer: Optional[str] = None
        self._value = 0
        self._events: List[LineEvent] = []

    @property
    def _where(self):
        return (self._chip._chain,) + self._chip._chip_and_pin(self._offset)

    def offset(self) -> int:
        return self._offset

    def name(self) -> str:
        k, pin = self._chip._chip_and_pin(self._offset)
        return PINS[pin] if self._chip._chips == 1 else f"{PINS[pin]}{k}"

    def consumer(self) -> Optional[str]:
        return self._consumer

    def owner(self) -> "GpioChip":
        return self._chip

    def is_requested(self) -> bool:
        return self._type is not None

    def direction(self) -> int:
        return self.DIRECTION_OUTPUT if self._type == LINE_REQ_DIR_OUT else self.DIRECTION_INPUT

    def request(self, consumer: str = "", type: int = LINE_REQ_DIR_AS_IS, flags: int = 0,
                default_val: Optional[int] = None, default_vals: Optional[Sequence[int]] = None) -> None:
        if self._type is not None:
            raise OSError(errno.EBUSY, os.strerror(errno.EBUSY), self.name())
        if type not in range(LINE_REQ_DIR_AS_IS, LINE_REQ_EV_BOTH_EDGES + 1):
            raise ValueError(f"request type {type}")
        if default_vals:
            default_val = default_vals[0]
        self._type, self._flags, self._consumer = type, flags, consumer
        core = self._chip._board._core
        if type >= LINE_REQ_EV_FALLING_EDGE:
            core.watch(*self._where, True)
        elif type == LINE_REQ_DIR_OUT:
            self.set_value(default_val or 0)

    def release(self) -> None:
        if self._type is not None and self._type >= LINE_REQ_EV_FALLING_EDGE:
            self._chip._board._core.watch(*self._where, False)
        self._type = None
        self._consumer = None
        self._events = []

    def _logical(self, physical: bool) -> int:
        return int(physical) ^ (1 if self._flags & LINE_REQ_FLAG_ACTIVE_LOW else 0)

    def _needs_request(self) -> None:
        if self._type is None:
            raise PermissionError(errno.EPERM, "the line is not requested", self.name())

    def get_value(self) -> int:
        """The line's value now (active-low applied when requested so)."""
        self._needs_request()
        if self._type == LINE_REQ_DIR_OUT:
            return self._value
        core = self._chip._board._core
        if PINS[self._where[2]] in ("BUSY", "FLAG"):
            core.note_output_read(*self._where)  # the driver looks (coverage: BUSY, FLAG's alarms observed)
        return self._logical(core.level(*self._where))

    def set_value(self, value: int) -> None:
        """Drives an output line (SW, STCK, STBY_RST and DIR reach the chip; BUSY and FLAG are the chip's;
        the DIR line of a chip without a DIR pin is connected to nothing)."""
        self._needs_request()
        if self._type != LINE_REQ_DIR_OUT:
            raise PermissionError(errno.EPERM, "the line is not an output", self.name())
        self._value = 1 if value else 0
        chain, chip, pin = self._where
        core = self._chip._board._core
        if PINS[pin] in ("BUSY", "FLAG") or not core.has_pin(chain, chip, pin):
            return  # the chip drives it (the host reads back its own value), or has no such pin
        core.drive(chain, chip, pin, bool(self._logical(bool(self._value))))

    def _collect(self) -> None:
        edges, _dropped = self._chip._board._core.take_edges(*self._where)
        for tick, level in edges:
            kind = LineEvent.RISING_EDGE if self._logical(level) else LineEvent.FALLING_EDGE
            if (self._type == LINE_REQ_EV_RISING_EDGE and kind != LineEvent.RISING_EDGE) or \
               (self._type == LINE_REQ_EV_FALLING_EDGE and kind != LineEvent.FALLING_EDGE):
                continue
            self._events.append(LineEvent(kind, tick, self))

    def event_wait(self, sec: int = 0, nsec: int = 0) -> bool:
        """Whether an edge event is pending, waiting up to sec + nsec of virtual time for one
        (the board's time stops at the edge)."""
        if self._type is None or self._type < LINE_REQ_EV_FALLING_EDGE:
            raise PermissionError(errno.EPERM, "the line is not requested for events", self.name())
        core = self._chip._board._core
        deadline = core.now() + (sec * 1_000_000_000 + nsec) // _NS_PER_TICK
        self._collect()
        while not self._events:
            if not core.wait_edge(*self._where, deadline):
                return False
            self._collect()
        return True

    def wait_edge(self, timeout: float) -> Optional[LineEvent]:
        """event_wait then event_read in one: the next edge within `timeout` seconds, or None."""
        sec = int(timeout)
        return self.event_read() if self.event_wait(sec, int(round((timeout - sec) * 1e9))) else None

    def _hand_out(self, event: LineEvent) -> LineEvent:
        """An edge event given to the driver: a read of the pin, and an edge it waited on."""
        chain, chip, pin = self._where
        if PINS[pin] in ("BUSY", "FLAG"):
            rising = (event.type == LineEvent.RISING_EDGE) != bool(self._flags & LINE_REQ_FLAG_ACTIVE_LOW)
            self._chip._board._core.note_output_edge(chain, chip, pin, rising)
        return event

    def event_read(self) -> LineEvent:
        """The oldest pending event (waits for one without a time limit, as a blocking read)."""
        while not self._events:
            self.event_wait(sec=3600)
        return self._hand_out(self._events.pop(0))

    def event_read_multiple(self) -> List[LineEvent]:
        self.event_wait()
        events, self._events = self._events, []
        return [self._hand_out(e) for e in events]

    def __repr__(self):
        return f"Line({self._chip.name()}, {self._offset}, {self.name()})"


class LineBulk:
    """Several lines of one gpiochip, as gpiod.LineBulk."""

    def __init__(self, lines: Iterable[Line]):
        self._lines = list(lines)

    def to_list(self) -> List[Line]:
        return list(self._lines)

    def __iter__(self):
        return iter(self._lines)

    def __len__(self):
        return len(self._lines)

    def request(self, consumer: str = "", type: int = LINE_REQ_DIR_AS_IS, flags: int = 0,
                default_vals: Optional[Sequence[int]] = None) -> None:
        for k, line in enumerate(self._lines):
            line.request(consumer, type, flags, default_val=default_vals[k] if default_vals else None)

    def release(self) -> None:
        for line in self._lines:
            line.release()

    def get_values(self) -> List[int]:
        return [line.get_value() for line in self._lines]

    def set_values(self, values: Sequence[int]) -> None:
        for line, v in zip(self._lines, values):
            line.set_value(v)

    def event_wait(self, sec: int = 0, nsec: int = 0) -> Optional["LineBulk"]:
        """The lines with pending events, waiting up to sec + nsec of virtual time; None on timeout."""
        core = self._lines[0]._chip._board._core if self._lines else None
        if core is None:
            return None
        deadline = core.now() + (sec * 1_000_000_000 + nsec) // _NS_PER_TICK
        while True:
            for line in self._lines:
                line._collect()
            ready = [line for line in self._lines if line._events]
            if ready:
                return LineBulk(ready)
            # Run to the earliest edge of any watched pin (or the deadline), then look again.
            nxt = core.next_edge_tick()
            if core.now() >= deadline:
                return None
            core.advance_to(deadline if nxt is None or nxt > deadline else max(nxt, core.now() + 1))


class GpioChip:
    """An emulated gpiochip (the pins of one chain), as gpiod.Chip: name, label, num_lines,
    get_line, get_lines, get_all_lines, find_line. Line offset = 5 * chip + pin (PINS order) for
    the first five pins; on a chain with an L6474, whose DIR pin the others lack, one DIR line per
    chip after them: offset = 5 * chips + chip (as the preload library's gpiochips)."""

    def __init__(self, board: Board, chain: int):
        self._board = board
        self._chain = chain
        self._chips = board._core.chip_count(chain)
        dir_index = PINS.index("DIR")
        self._dir = any(board._core.has_pin(chain, k, dir_index) for k in range(self._chips))
        self._lines = [Line(self, k) for k in range((6 if self._dir else 5) * self._chips)]

    def _offset(self, chip: int, pin: int) -> int:
        """The line offset of pin index `pin` of chip `chip`."""
        if PINS[pin] == "DIR":
            if not self._dir:
                raise ValueError(f"no chip of {self.name()} has a DIR pin (the L6474's)")
            return 5 * self._chips + chip
        return 5 * chip + pin

    def _chip_and_pin(self, offset: int):
        """(chip, pin index) of a line offset."""
        if offset >= 5 * self._chips:
            return offset - 5 * self._chips, PINS.index("DIR")
        return offset // 5, offset % 5

    def name(self) -> str:
        n = self._board._core.gpiochip(self._chain)
        return f"gpiochip{n}" if n is not None else f"gpiochip-{self._board._core.chain_name(self._chain)}"

    def label(self) -> str:
        return f"l6470emu {self._board._core.chain_name(self._chain)}"

    def num_lines(self) -> int:
        return len(self._lines)

    def get_line(self, offset: int) -> Line:
        if not 0 <= offset < len(self._lines):
            raise ValueError(f"line offset {offset}: 0..{len(self._lines) - 1}")
        return self._lines[offset]

    def get_lines(self, offsets: Sequence[int]) -> LineBulk:
        return LineBulk(self.get_line(o) for o in offsets)

    def get_all_lines(self) -> LineBulk:
        return LineBulk(self._lines)

    def find_line(self, name: str) -> Optional[Line]:
        for line in self._lines:
            if line.name() == name:
                return line
        return None

    def close(self) -> None:
        for line in self._lines:
            line.release()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
