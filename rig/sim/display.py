"""A simulated display: vertical blanks, top-to-bottom scan-out and sample-and-hold.

Refresh k starts at its vertical blank `t0 + k / refresh_hz`. Rows are scanned out from the top
(row fraction 0) to the bottom (row fraction 1) over `scanout_fraction` of the refresh period, and
each row keeps emitting what it was last given until it is scanned out again (sample-and-hold,
no black insertion). A frame handed over at time t appears at the first vertical blank strictly
after t: a swap requested exactly at a blank has missed it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rig.errors import ConfigError

COMMON_REFRESH_HZ = (60.0, 90.0, 120.0, 144.0)
_ROUNDING = 1e-9


@dataclass(frozen=True)
class DisplayConfig:
    refresh_hz: float = 60.0
    width: int = 320
    height: int = 240
    scanout_fraction: float = 1.0
    t0: float = 0.0

    def __post_init__(self) -> None:
        if not (np.isfinite(self.refresh_hz) and 1.0 <= self.refresh_hz <= 1000.0):
            raise ConfigError(f"display refresh rate must be 1-1000 Hz, got {self.refresh_hz}")
        if self.width < 16 or self.height < 16:
            raise ConfigError(f"display resolution must be at least 16x16, got {self.width}x{self.height}")
        if not 0.0 < self.scanout_fraction <= 1.0:
            raise ConfigError(f"scan-out fraction must be in (0, 1], got {self.scanout_fraction}")


class Display:
    """Timing of a display; which refresh each row shows at any time."""

    def __init__(self, config: DisplayConfig) -> None:
        self.config = config
        self.period_s = 1.0 / config.refresh_hz

    def vblank_time(self, k: int) -> float:
        """Start of refresh k (s); k may also be an integer array."""
        return self.config.t0 + k * self.period_s

    def refresh_after(self, t: float) -> int:
        """Index of the first vertical blank strictly after time t: when a frame handed over at t appears.

        A time within a nanosecond-scale rounding error of a blank counts as at that blank.
        """
        return int(np.floor((t - self.config.t0) / self.period_s + _ROUNDING)) + 1

    def scanout_delay(self, row_fraction: float | np.ndarray) -> float | np.ndarray:
        """Time from the vertical blank until the row at `row_fraction` (0 top, 1 bottom) is lit."""
        return np.clip(row_fraction, 0.0, 1.0) * self.config.scanout_fraction * self.period_s

    def photon_time(self, k: int, row_fraction: float) -> float:
        """When refresh k's content reaches the row at `row_fraction`."""
        return float(self.vblank_time(k) + self.scanout_delay(row_fraction))

    def refresh_shown(self, t: np.ndarray, row_fraction: np.ndarray) -> np.ndarray:
        """Index of the refresh that row `row_fraction` shows at time t (broadcast); -1 before the first."""
        since = np.asarray(t) - self.config.t0 - self.scanout_delay(np.asarray(row_fraction))
        return np.maximum(np.floor(since / self.period_s).astype(np.int64), -1)
