"""A frame clock for the self-test: refreshes at a fixed rate on the rig clock, given to the window
in place of a monitor's (virtual X servers do not pace swaps)."""

from __future__ import annotations

import math

from rig.clock import Clock

START_DELAY_S = 0.05


class FixedRateFrameClock:
    """Refresh k's blank at `t0 + k / refresh_hz`, t0 a little after `start`."""

    def __init__(self, refresh_hz: float) -> None:
        self.refresh_hz = refresh_hz
        self.t0 = 0.0

    def start(self, clock: Clock) -> None:
        self.t0 = clock.now() + START_DELAY_S

    def vblank(self, k: int) -> float:
        return self.t0 + k / self.refresh_hz

    def refresh_after(self, t: float) -> int:
        return max(0, math.floor((t - self.t0) * self.refresh_hz + 1e-9) + 1)
