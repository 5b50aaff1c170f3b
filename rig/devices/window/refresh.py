"""A display's refreshes as the swaps report them: `RefreshModel` fits vertical blanks
`t0 + k * period` to the times buffer swaps returned (or the driver said its blanks were), assigns
each swap its refresh, and keeps the fit up to date as the display's clock drifts against the rig's.

Swap-return times lag the blank by a small, variable amount; the fit's phase follows their lower
edge (a low quantile of the residuals), the blank itself, and its slope the period. A display that
does not pace swaps (vsync off, a virtual X server) is refused at the fit: its intervals are far
below any monitor's refresh period or scattered.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from rig.errors import RigError

MIN_PERIOD_S = 1.0 / 500.0
"""Swaps returning faster than this are not paced by a refresh."""
MAX_PERIOD_S = 1.0 / 20.0
FIT_WINDOW = 240
"""Latest swaps the fit follows."""
REFIT_EVERY = 30
PHASE_QUANTILE = 0.1
# A swap more than this fraction of a period from every fitted blank was not paced.
SLOT_TOLERANCE = 0.35


class RefreshModel:
    """Vertical blank k at `t0 + k * period_s` (rig seconds)."""

    def __init__(self, t0: float, period_s: float) -> None:
        if not (math.isfinite(period_s) and period_s > 0.0):
            raise ValueError(f"a refresh period must be positive, got {period_s!r}")
        self.t0 = float(t0)
        self.period_s = float(period_s)
        self._k: deque[int] = deque(maxlen=FIT_WINDOW)
        self._t: deque[float] = deque(maxlen=FIT_WINDOW)
        self._since_fit = 0

    @property
    def refresh_hz(self) -> float:
        return 1.0 / self.period_s

    @classmethod
    def fit(cls, times: np.ndarray, what: str = "buffer swaps") -> RefreshModel:
        """The model of consecutive swap times (at least 3), refresh 0 at the first; RigError when
        they are not paced by a refresh."""
        times = np.asarray(times, dtype=np.float64)
        if times.size < 3:
            raise ValueError("fitting refreshes needs at least three swap times")
        steps = np.diff(times)
        median = float(np.median(steps))
        if not MIN_PERIOD_S <= median <= MAX_PERIOD_S:
            raise RigError(
                f"the display's {what} come every {median * 1e3:.3f} ms, which no monitor's refresh explains: "
                "vsync is off (turn it on in the driver's settings) or this is a virtual X server, which does not "
                "pace swaps"
            )
        slots = np.rint((times - times[0]) / median)
        model = cls(times[0], median)
        model._refit(slots.astype(np.int64), times)
        residual = np.abs(times - model.vblank(slots)) / model.period_s
        if np.count_nonzero(residual > SLOT_TOLERANCE) > times.size // 4:
            raise RigError(
                f"the display's {what} are not regular (a quarter or more lie far from any refresh): another program "
                "may be loading the GPU, or the compositor is pacing swaps; close it or use full screen"
            )
        for k, t in zip(slots.tolist(), times.tolist()):
            model._k.append(int(k))
            model._t.append(t)
        return model

    def vblank(self, k: int | np.ndarray) -> float | np.ndarray:
        return self.t0 + np.asarray(k) * self.period_s if isinstance(k, np.ndarray) else self.t0 + k * self.period_s

    def refresh_after(self, t: float) -> int:
        """The first refresh whose blank is strictly after `t`."""
        return int(math.floor((t - self.t0) / self.period_s + 1e-9)) + 1

    def slot(self, t: float) -> int:
        """The refresh a swap (or driver blank) reported at `t` belongs to: the nearest blank."""
        return int(round((t - self.t0) / self.period_s))

    def observe(self, k: int, t: float) -> None:
        """Refresh k was reported at `t`: follow it (the fit is redone every REFIT_EVERY reports)."""
        self._k.append(k)
        self._t.append(t)
        self._since_fit += 1
        if self._since_fit >= REFIT_EVERY and len(self._k) >= REFIT_EVERY:
            self._refit(np.fromiter(self._k, np.int64), np.fromiter(self._t, np.float64))

    def _refit(self, k: np.ndarray, t: np.ndarray) -> None:
        self._since_fit = 0
        if np.ptp(k) > 0:
            slope, _ = np.polyfit(k.astype(np.float64), t, 1)
            self.period_s = float(slope)
        residual = t - k * self.period_s
        self.t0 = float(np.quantile(residual, PHASE_QUANTILE))
