"""Ending a live run when the pendulum stops: `SwingWatch` watches a tracker's samples (a tap,
`rig.devices.tap`) and compares each `WINDOW_S` of their swing (the positions' peak-to-peak
extent) with the first; once it has fallen below `STILL_FRACTION` of it, the swing has died away
and `stopped` is set."""

from __future__ import annotations

import numpy as np

from predictors import PoseSample

WINDOW_S = 2.0
STILL_FRACTION = 0.1


class RunEnded(Exception):
    """The run is over before its duration for a reason that is no error (the pendulum stopped)."""


class SwingWatch:
    """Watches the swing of the samples it is shown."""

    def __init__(self) -> None:
        self.stopped = False
        self._first_extent: float | None = None
        self._window: list[np.ndarray] = []
        self._window_start: float | None = None

    def __call__(self, samples: list[PoseSample]) -> None:
        for sample in samples:
            if self._window_start is None:
                self._window_start = sample.t_sensor
            if sample.t_sensor - self._window_start >= WINDOW_S:
                extent = float(np.linalg.norm(np.ptp(np.array(self._window), axis=0)))
                self._first_extent = extent if self._first_extent is None else self._first_extent
                self.stopped = self.stopped or extent < STILL_FRACTION * self._first_extent
                self._window, self._window_start = [], sample.t_sensor
            self._window.append(sample.position)
