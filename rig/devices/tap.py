"""A tracker source whose samples are also shown, as they are handed on, to observers (the rig's
LSL outlet, the live run's swing watch), without the session knowing."""

from __future__ import annotations

from typing import Any, Callable

from predictors import PoseSample
from rig.clock import Clock
from rig.devices.protocols import Fault, TrackerSource

Tap = Callable[[list[PoseSample]], None]


class TappedTracker:
    """`tracker`, every batch of samples it hands on passed to each of `taps` first."""

    def __init__(self, tracker: TrackerSource, *taps: Tap) -> None:
        self.tracker = tracker
        self._taps = taps

    def connect(self, clock: Clock) -> None:
        self.tracker.connect(clock)

    def poll(self) -> list[PoseSample]:
        return self._tapped(self.tracker.poll())

    def wait(self, timeout_s: float) -> list[PoseSample]:
        return self._tapped(self.tracker.wait(timeout_s))

    def fault(self) -> Fault | None:
        return self.tracker.fault()

    def report(self) -> dict[str, Any]:
        return self.tracker.report()

    def close(self) -> None:
        self.tracker.close()

    def _tapped(self, samples: list[PoseSample]) -> list[PoseSample]:
        for tap in self._taps:
            tap(samples)
        return samples
