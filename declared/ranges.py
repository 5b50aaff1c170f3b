"""The numbers a setting may take (`Range`), and how they read in a message."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Range:
    """From `low` to `high`, each end included where `includes_low` / `includes_high` says. An
    infinite end is a value only where it is included (a Q factor of inf: no damping); NaN never is."""

    low: float
    high: float = math.inf
    includes_low: bool = False
    includes_high: bool = False

    def contains(self, value: float) -> bool:
        """Whether `value` is in the range."""
        above = self.low <= value if self.includes_low else self.low < value
        below = value <= self.high if self.includes_high else value < self.high
        return above and below

    def describe(self, unit: str) -> str:
        """The range in words, for messages and help: "a positive number of seconds from 0.5 to 3600"."""
        closed = self.includes_low and self.includes_high and math.isfinite(self.low) and math.isfinite(self.high)
        if self.low == 0.0 and self.includes_low:
            kind = "a number" if closed else "zero or a positive number"
        else:
            kind = "a positive number" if self.low >= 0.0 else "a number"
        lower = f"{'at least' if self.includes_low else 'above'} {self.low:g}" if self.low not in (0.0, -math.inf) else ""
        upper = f"{'at most' if self.includes_high else 'below'} {self.high:g}" if self.high != math.inf else ""
        if closed:
            bounds = f"from {self.low:g} to {self.high:g}"
        else:
            bounds = " and ".join(part for part in (lower, upper) if part)
        return " ".join(part for part in (kind, f"of {unit}" if unit else "", bounds) if part)

    def clipped(self, value: float) -> float:
        """`value` moved onto the end it passes, where the range holds that end (an open end has no
        nearest value inside: a value past it is returned as it is)."""
        if self.includes_low and value < self.low:
            return self.low
        if self.includes_high and value > self.high:
            return self.high
        return value

    def scaled(self, factor: float) -> Range:
        """The same range in a unit `factor` times smaller (seconds as milliseconds: 1e3)."""
        return Range(self.low * factor, self.high * factor, self.includes_low, self.includes_high)


POSITIVE = Range(0.0)
NON_NEGATIVE = Range(0.0, includes_low=True)
OPEN_UNIT = Range(0.0, 1.0)
"""A share strictly between none and all (a smoothing factor)."""
FRACTION = Range(0.0, 1.0, includes_low=True)
"""Zero up to, not including, the whole (a probability of loss, a phase within a period)."""
ANY = Range(-math.inf)
"""Any finite number."""
