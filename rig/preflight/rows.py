"""One line of a pre-flight check: a device, what was checked, pass / warn / fail, what was measured
and, where it is not a pass, what to fix."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

PASS, WARN, FAIL = "pass", "warn", "fail"
STATUSES = (PASS, WARN, FAIL)
"""From best to worst: a check's overall status is its worst row's."""


@dataclass(frozen=True)
class CheckRow:
    """`device` (display, camera, tracker, disk), `what` it was checked for, the `status`, the
    `measured` result in words, `fix` (what to do; empty for a pass), and the numbers behind it."""

    device: str
    what: str
    status: str
    measured: str
    fix: str = ""
    values: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"a check's status is one of {', '.join(STATUSES)}, got {self.status!r}")


def worst(rows: list[CheckRow]) -> str:
    """The overall status: fail if any row failed, else warn if any warned, else pass."""
    return max((row.status for row in rows), key=STATUSES.index, default=PASS)


def graded(value: float, warn_below: float, fail_below: float) -> str:
    """PASS at or above `warn_below`, WARN down to `fail_below`, FAIL below it."""
    return PASS if value >= warn_below else WARN if value >= fail_below else FAIL


def failed(device: str, what: str, reason: str, fix: str) -> CheckRow:
    """The row of a device that could not be checked at all (it would not open, or gave nothing)."""
    return CheckRow(device, what, FAIL, reason, fix)
