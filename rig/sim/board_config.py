"""The simulated board's settings, each declared on its field: what the command line's options are made
from, without the simulation's numerical libraries (`rig.sim.board` simulates the board)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

from declared import Range, check, setting
from rig.board.protocol import protocol
from rig.errors import ConfigError

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import ArrayLike, NDArray

    from analysis.board.blink_code import BlinkSchedule

MIN_COUNTS_PER_REV = 4


@dataclass(frozen=True)
class SimulatedBoardConfig:
    """The simulated board: its clock offset (board time = simulation time + board_offset_s), its
    blink (as `rig board blink` asks for it) and its encoder's resolution, each declared on its field."""

    board_offset_s: float = setting(
        100.0, "seconds", "how far the board's clock runs ahead of the simulation's, within a day",
        Range(-86400.0, 86400.0, True, True),
    )  # fmt: skip
    blink_start_s: float = setting(0.25, "seconds", "simulation time bit 0 of the blink starts", Range(0.0, 3600.0, True, True))
    blink_bits: int = setting(
        64, "bits", "bits in the blink code (a 16-bit count), as many as the board's protocol allows",
        Range(1.0, 65535.0, True, True),
    )  # fmt: skip
    blink_bit_s: float = setting(0.05, "seconds", "how long each bit lasts, at least the board's shortest", Range(0.0, 10.0, includes_high=True))
    blink_seed: int = setting(0xACE1, "", "seed of the blink code", Range(1.0, 65535.0, True, True))
    blink_level: int = setting(255, "", "the LED's drive level while lit", Range(1.0, 255.0, True, True))
    counts_per_rev: int = setting(
        2400, "counts", "encoder counts per revolution of the pendulum", Range(MIN_COUNTS_PER_REV, 1e6, True, True)
    )

    def __post_init__(self) -> None:
        check(self, ConfigError, "board.")
        spec = protocol()  # the board's limits, from its protocol header
        if not 1 <= self.blink_bits <= spec["RIG_BLINK_MAX_BITS"]:
            raise ConfigError(f"the blink must have 1..{spec['RIG_BLINK_MAX_BITS']} bits, got {self.blink_bits!r}")
        shortest_bit = spec["RIG_BLINK_MIN_BIT_TICKS"] / spec["RIG_TICK_HZ"]
        if not (math.isfinite(self.blink_bit_s) and self.blink_bit_s >= shortest_bit):
            raise ConfigError(f"a blink bit must last at least {shortest_bit * 1e3:g} ms, got {self.blink_bit_s!r} s")

    @cached_property
    def code(self) -> NDArray[np.bool_]:
        """The blink's bits."""
        from analysis.board.blink_code import lfsr_bits  # here, not above: the settings are read without numpy

        return lfsr_bits(self.blink_seed, self.blink_bits)

    @property
    def blink_end_s(self) -> float:
        """Simulation time the last bit ends and the LED is on again."""
        return self.blink_start_s + self.blink_bits * self.blink_bit_s

    def schedule(self) -> BlinkSchedule:
        """The blink as the board plays it, on the board's clock."""
        from analysis.board.blink_code import BlinkSchedule

        return BlinkSchedule(
            start_board_time=self.blink_start_s + self.board_offset_s,
            bit_s=self.blink_bit_s,
            seed=self.blink_seed,
            bits=self.blink_bits,
            level=self.blink_level,
        )

    def led_level(self, t: ArrayLike) -> NDArray[np.int64]:
        """The LED's drive level (0..255) at simulation times t, the shape of t."""
        import numpy as np

        times = np.asarray(t, dtype=np.float64)
        index = np.floor((times - self.blink_start_s) / self.blink_bit_s)
        inside = (index >= 0) & (index < self.blink_bits)
        on = np.ones(times.shape, dtype=bool)
        on[inside] = self.code[index[inside].astype(np.int64)]
        return np.where(on, self.blink_level, 0)

    def led_changes(self, t_on: float) -> list[tuple[float, int, int | None]]:
        """(simulation time, level, bit) of every change of the LED, from switching it on at t_on
        (before the blink): bit is the blink bit that made the change, None a command."""
        changes: list[tuple[float, int, int | None]] = [(t_on, self.blink_level, None)]
        for k, bit in enumerate(self.code):
            level = self.blink_level if bit else 0
            if level != changes[-1][1]:
                changes.append((self.blink_start_s + k * self.blink_bit_s, level, k))
        if changes[-1][1] != self.blink_level:
            changes.append((self.blink_end_s, self.blink_level, None))
        return changes
