"""The rig clock: one time line, in seconds, that every timestamp of a run is on.

A simulation runs on a `VirtualClock`: time stands still until the session moves it on, so a run
is deterministic for a seed and takes as long as its computing does, not as long as the motion it
simulates. A live run runs on a `MonotonicClock`: the operating system's monotonic clock, read in
integer nanoseconds (never stepped by NTP, never going backwards), counted from the moment the
clock was made. Devices and the session see only the `Clock` interface, so the same session code
drives both.
"""

from __future__ import annotations

import time
from typing import Callable, Protocol, runtime_checkable

NS_PER_S = 1_000_000_000


@runtime_checkable
class Clock(Protocol):
    """Seconds on the rig's time line."""

    def now(self) -> float:
        """The current time (s)."""

    def wait_until(self, t: float) -> None:
        """Return once the time is `t` or later (at once if it already is)."""


class VirtualClock:
    """Simulated time: it moves only when told to, and never backwards."""

    def __init__(self, start: float = 0.0) -> None:
        self._t = float(start)

    def now(self) -> float:
        return self._t

    def wait_until(self, t: float) -> None:
        """Move the time on to `t`; a time already past leaves it where it is."""
        if t > self._t:
            self._t = float(t)


class MonotonicClock:
    """The operating system's monotonic clock, as seconds since this clock was made.

    `read_ns` and `sleep` are the system's by default; tests pass their own so that they neither
    sleep nor read the wall clock.
    """

    def __init__(
        self,
        read_ns: Callable[[], int] = time.monotonic_ns,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        self._read_ns = read_ns
        self._sleep = sleep
        self.on_system_clock = read_ns is time.monotonic_ns
        """Whether the time is the system's monotonic clock itself (CLOCK_MONOTONIC), which compiled
        code can read on its own, without a call into Python, and put on this time line."""
        self.origin_ns = read_ns()
        """The system's monotonic time (ns) at the clock's zero: convert a host timestamp `ns` taken
        with the same system clock to rig time as (ns - origin_ns) / 1e9."""

    def now_ns(self) -> int:
        """Nanoseconds since the clock was made."""
        return self._read_ns() - self.origin_ns

    def now(self) -> float:
        return self.now_ns() / NS_PER_S

    def wait_until(self, t: float) -> None:
        """Sleep until `t`; a sleep that ends early (a signal) is resumed, and Ctrl-C interrupts it."""
        while (remaining := t - self.now()) > 0.0:
            self._sleep(remaining)
