"""A terminal progress bar for long commands, drawn only when stderr is a terminal."""

from __future__ import annotations

import sys
import time
from typing import Callable, TextIO

from rig import interrupts

_WIDTH = 30


class ProgressBar:
    """Callable as progress(done, total); redraws when the shown percentage changes.

    With `unit` (say "videos") it also shows the count done and an estimate of the time left
    from the pace so far; `clock` (seconds) is the monotonic clock unless a test gives its own.
    """

    def __init__(
        self,
        label: str,
        stream: TextIO | None = None,
        enabled: bool | None = None,
        unit: str | None = None,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = self.stream.isatty() if enabled is None else enabled
        self.unit = unit
        self._clock = clock
        self._started = clock()
        self._shown = -1

    def __call__(self, done: float, total: float) -> None:
        interrupts.raise_pending()
        if not self.enabled or total <= 0:
            return
        percent = int(100 * min(max(done / total, 0.0), 1.0))
        if percent == self._shown and self.unit is None:
            return
        self._shown = percent
        filled = _WIDTH * percent // 100
        self.stream.write(f"\r{self.label} [{'#' * filled}{'.' * (_WIDTH - filled)}] {percent:3d}%{self._count(done, total)}")
        if percent == 100:
            self.stream.write("\n")
        self.stream.flush()

    def _count(self, done: float, total: float) -> str:
        if self.unit is None:
            return ""
        text = f" {done:g}/{total:g} {self.unit}"
        if 0 < done < total:
            left = (self._clock() - self._started) / done * (total - done)
            text += f", about {_duration(left)} left"
        return text


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"
