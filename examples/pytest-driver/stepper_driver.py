"""A small driver for a daisy chain of L6470s over py-spidev: the kind of module the Python guide's
pytest example tests. Nothing here knows about the emulator; on a board with real chips it
runs unchanged. Chip 0 is the one that drives MISO: in a frame of N bytes, byte k is chip k's.

    python3 stepper_driver.py --chips 2 --chip 1 --move -3200   # prints "chip 1 at -3200"
"""
import argparse
import time

import spidev


class StepperChain:
    """A chain of `chips` L6470s on /dev/spidev{bus}.{cs}."""

    def __init__(self, chips: int, bus: int = 0, cs: int = 0, speed_hz: int = 4_000_000):
        self.chips = chips
        self.spi = spidev.SpiDev()
        self.spi.open(bus, cs)
        self.spi.mode = 3  # CPOL = CPHA = 1, as the L6470 wants
        self.spi.max_speed_hz = speed_hz

    def command(self, chip: int, data: list) -> list:
        """Sends `data` to one chip (NOP to the others), one CS frame per byte; returns its answers."""
        answers = []
        for byte in data:
            frame = [0x00] * self.chips
            frame[chip] = byte
            answers.append(self.spi.xfer2(frame)[chip])
        return answers

    def status(self, chip: int) -> int:
        """GetStatus (clears the latched flags)."""
        a = self.command(chip, [0xD0, 0, 0])
        return a[1] << 8 | a[2]

    def position(self, chip: int) -> int:
        """ABS_POS in microsteps (22-bit two's complement)."""
        a = self.command(chip, [0x21, 0, 0, 0])
        value = a[1] << 16 | a[2] << 8 | a[3]
        return value - (1 << 22) if value & 0x200000 else value

    def move(self, chip: int, steps: int) -> None:
        """Move by `steps` microsteps (negative = reverse)."""
        n = abs(steps)
        self.command(chip, [0x40 | (steps >= 0), n >> 16 & 0x3F, n >> 8 & 0xFF, n & 0xFF])

    def wait_idle(self, chip: int, timeout_s: float = 5.0) -> None:
        """Polls STATUS until BUSY (active low) goes high."""
        deadline = time.monotonic() + timeout_s
        while not self.status(chip) & 0x0002:
            if time.monotonic() > deadline:
                raise TimeoutError(f"chip {chip} still busy after {timeout_s} s")
            time.sleep(0.001)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--chips", type=int, default=1)
    parser.add_argument("--chip", type=int, default=0)
    parser.add_argument("--move", type=int, required=True, help="microsteps, negative = reverse")
    args = parser.parse_args()
    chain = StepperChain(args.chips)
    chain.status(args.chip)  # clear the power-up UVLO flag
    chain.move(args.chip, args.move)
    chain.wait_idle(args.chip)
    print(f"chip {args.chip} at {chain.position(args.chip)}")


if __name__ == "__main__":
    main()
