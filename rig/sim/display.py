"""A simulated display: vertical blanks, top-to-bottom scan-out and sample-and-hold.

Refresh k starts at its vertical blank `t0 + (k + phase) / refresh_hz`. In a simulated run t0 is
the rig clock's start, the warm-up before the camera's first frame (often a whole number of
refreshes, so that refreshes start with camera frames); `phase` (a fraction of a refresh) shifts
the refreshes against the camera's frames, as an independent display clock does in a lab. Rows are scanned out from the top (row fraction 0) to the bottom (row fraction 1) over `scanout_fraction` of the refresh period, and
each row keeps emitting what it was last given until it is scanned out again (sample-and-hold,
no black insertion). A frame handed over at time t appears at the first vertical blank strictly
after t (a swap requested exactly at a blank has missed it), and at most one new frame appears
per refresh, as with a double-buffered swap chain under vsync.

`SimDisplay` keeps the images it shows for as long as a camera may still film them
(`rig.sim.camera`): the few refreshes before the newest one the run has reached.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from rig.clock import Clock
from rig.devices.protocols import NO_IMAGE
from rig.sim.display_config import DisplayConfig

_ROUNDING = 1e-9
# Images are kept until no refresh among the last this many shows them.
_KEEP_REFRESHES = 4


class SimDisplay:
    """The simulated twin of a display (`rig.devices.protocols.Display`)."""

    def __init__(self, config: DisplayConfig) -> None:
        self.config = config
        self.width = config.width
        self.height = config.height
        self.refresh_hz = config.refresh_hz
        self.period_s = 1.0 / config.refresh_hz
        self.content: list[int] = []
        """The image id each refresh reached so far shows (NO_IMAGE: dark)."""
        self.images: dict[int, np.ndarray] = {}
        """The images refreshes may still show or a camera still film, by id."""
        self._presents: list[tuple[int, int]] = []
        self._last_present = -1
        self._current = NO_IMAGE

    def connect(self, clock: Clock) -> None:
        """Nothing to open: the simulated display's timing is its configuration's."""

    def report(self) -> dict[str, Any]:
        return {"display": "sim", "refresh_hz": self.refresh_hz, "scanout_fraction": self.config.scanout_fraction,
                "refreshes": len(self.content)}  # fmt: skip

    def close(self) -> None:
        """Nothing to release."""

    def vblank_time(self, k: int) -> float:
        """Start of refresh k (s); k may also be an integer array."""
        return self.config.origin + k * self.period_s

    def refresh_after(self, t: float) -> int:
        """Index of the first vertical blank strictly after time t: when a frame handed over at t appears.

        A time within a nanosecond-scale rounding error of a blank counts as at that blank.
        """
        return int(np.floor((t - self.config.origin) / self.period_s + _ROUNDING)) + 1

    def scanout_delay(self, row_fraction: float | np.ndarray) -> float | np.ndarray:
        """Time from the vertical blank until the row at `row_fraction` (0 top, 1 bottom) is lit."""
        return np.clip(row_fraction, 0.0, 1.0) * self.config.scanout_fraction * self.period_s

    def photon_time(self, k: int, row_fraction: float) -> float:
        """When refresh k's content reaches the row at `row_fraction`."""
        return float(self.vblank_time(k) + self.scanout_delay(row_fraction))

    def refresh_shown(self, t: np.ndarray, row_fraction: np.ndarray) -> np.ndarray:
        """Index of the refresh that row `row_fraction` shows at time t (broadcast); -1 before the first."""
        since = np.asarray(t) - self.config.origin - self.scanout_delay(np.asarray(row_fraction))
        return np.maximum(np.floor(since / self.period_s).astype(np.int64), -1)

    def present(self, image: np.ndarray, t_ready: float, image_id: int) -> int:
        """Show `image` from the first blank after `t_ready`, but no sooner than one refresh after
        the previous image, nor at a refresh whose content `shown` has already given; the refresh
        it appears at."""
        refresh = max(self.refresh_after(t_ready), self._last_present + 1, len(self.content))
        self._last_present = refresh
        self._presents.append((refresh, image_id))
        self.images[image_id] = image
        return refresh

    def shown(self, k: int) -> int:
        """The newest image presented for refresh k or earlier; k must be the next refresh in turn."""
        if k != len(self.content):
            raise ValueError(f"refresh {k} asked for out of turn; the next one is {len(self.content)}")
        if self.content:
            # a camera has filmed everything up to refresh k by now (it films as soon as it can)
            oldest_needed = min(self.content[max(0, k - 1 - _KEEP_REFRESHES) :])
            for image_id in [i for i in self.images if i < oldest_needed]:
                del self.images[image_id]
        while self._presents and self._presents[0][0] <= k:
            self._current = self._presents.pop(0)[1]
        self.content.append(self._current)
        return self._current

    @property
    def settled_until(self) -> float:
        """Until when what every row emits is known: the start of the first refresh not reached yet."""
        return self.vblank_time(len(self.content))
