"""A terminal progress bar for long commands, drawn only when stderr is a terminal."""

from __future__ import annotations

import sys
from typing import TextIO

_WIDTH = 30


class ProgressBar:
    """Callable as progress(done, total); redraws when the shown percentage changes."""

    def __init__(self, label: str, stream: TextIO | None = None, enabled: bool | None = None) -> None:
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = self.stream.isatty() if enabled is None else enabled
        self._shown = -1

    def __call__(self, done: float, total: float) -> None:
        if not self.enabled or total <= 0:
            return
        percent = int(100 * min(max(done / total, 0.0), 1.0))
        if percent == self._shown:
            return
        self._shown = percent
        filled = _WIDTH * percent // 100
        self.stream.write(f"\r{self.label} [{'#' * filled}{'.' * (_WIDTH - filled)}] {percent:3d}%")
        if percent == 100:
            self.stream.write("\n")
        self.stream.flush()
