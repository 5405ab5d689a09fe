"""STATUS as an int with its flags by datasheet name. The decoding is core/status.hpp's
describe_status() for the chip's own layout (the extension passes its words in); this class
only makes them attributes, so STATUS reads the same here as in `l6470emu decode`."""

# Every word describe_status() can produce: flags in positive logic (present = active).
_FLAGS = frozenset({
    "HiZ", "BUSY", "SW_F", "SW_EVN", "FWD", "REV", "STOPPED", "ACC", "DEC", "CONST",
    "CMD_ERROR", "NOTPERF_CMD", "WRONG_CMD", "UVLO", "UVLO_ADC", "TH_WRN", "TH_SD",
    "TH_WARNING", "TH_BRIDGE_SHUTDOWN", "TH_DEVICE_SHUTDOWN", "OCD",
    "STEP_LOSS_A", "STEP_LOSS_B", "STALL_A", "STALL_B", "SCK_MOD",
})
_MOTION = ("STOPPED", "ACC", "DEC", "CONST")


class Status(int):
    """A STATUS word (an int) with its flags decoded for the chip's variant.

    Flags are attributes named as in the datasheet, in positive logic: ``status.UVLO`` is
    True while undervoltage is latched (the bit itself is active low), ``status.BUSY`` while
    a command runs. ``status.names`` holds the active ones; ``"OCD" in status`` works too.
    """

    names: frozenset
    description: str
    variant: str

    def __new__(cls, value: int, description: str, variant: str = ""):
        self = super().__new__(cls, value)
        self.description = description
        self.names = frozenset(description.split())
        self.variant = variant
        return self

    def __getattr__(self, name: str) -> bool:
        if name in _FLAGS:
            return name in self.names
        raise AttributeError(f"STATUS has no flag {name!r} (flags: {', '.join(sorted(_FLAGS))})")

    def __contains__(self, name: object) -> bool:
        return name in self.names

    @property
    def mot_status(self) -> str:
        """MOT_STATUS: "STOPPED", "ACC", "DEC" or "CONST"."""
        return next((m for m in _MOTION if m in self.names), "STOPPED")

    @property
    def forward(self) -> bool:
        """DIR: True = forward."""
        return "FWD" in self.names

    def __repr__(self) -> str:
        return f"Status(0x{int(self):04X}: {self.description})"

    def __reduce__(self):
        return (Status, (int(self), self.description, self.variant))
