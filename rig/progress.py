"""Progress of a long command on stderr: a bar redrawn in place on a terminal; elsewhere (a pipe, a
log file, CI) one line every few seconds, so that a piped run shows it is alive without filling
the log."""

from __future__ import annotations

import sys
import time
from typing import Callable, TextIO

from rig import interrupts

_WIDTH = 30
LINE_EVERY_S = 5.0
"""Off a terminal, the seconds between two lines; a command done sooner prints none."""


class ProgressBar:
    """Callable as progress(done, total).

    On a terminal (`terminal`, by default whether the stream is one) it redraws a bar when the shown
    percentage changes. Elsewhere it writes a line once `every_s` seconds have passed since the
    start, then at most one every `every_s`, and a last one when the work is done if it wrote any
    before. With `unit` (say "videos") it shows the count done; a line, and a bar with a unit, give
    an estimate of the time left from the pace so far. `enabled=False` shows nothing. `clock`
    (seconds) is the monotonic clock unless a test gives its own.
    """

    def __init__(
        self,
        label: str,
        stream: TextIO | None = None,
        enabled: bool = True,
        unit: str | None = None,
        clock: Callable[[], float] = time.monotonic,
        terminal: bool | None = None,
        every_s: float = LINE_EVERY_S,
    ) -> None:
        self.label = label
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = enabled
        self.terminal = _is_terminal(self.stream) if terminal is None else terminal
        self.unit = unit
        self.every_s = every_s
        self._clock = clock
        self._started = clock()
        self._shown = -1
        self._line_at: float | None = None
        self._finished = False

    def __call__(self, done: float, total: float) -> None:
        interrupts.raise_pending()
        if not self.enabled or total <= 0:
            return
        if self.terminal:
            self._draw(done, total)
        else:
            self._line(done, total)

    def _draw(self, done: float, total: float) -> None:
        percent = _percent(done, total)
        if percent == self._shown and self.unit is None:
            return
        self._shown = percent
        filled = _WIDTH * percent // 100
        left = self._left(done, total) if self.unit is not None else ""
        self.stream.write(f"\r{self.label} [{'#' * filled}{'.' * (_WIDTH - filled)}] {percent:3d}%{self._count(done, total)}{left}")
        if percent == 100:
            self.stream.write("\n")
        self.stream.flush()

    def _line(self, done: float, total: float) -> None:
        now = self._clock()
        finished = done >= total
        if finished:
            if self._line_at is None or self._finished:
                return
            self._finished = True
        elif now - (self._line_at if self._line_at is not None else self._started) < self.every_s:
            return
        self._line_at = now
        self.stream.write(f"{self.label}: {_percent(done, total)}%{self._count(done, total)}{self._left(done, total)}\n")
        self.stream.flush()

    def _count(self, done: float, total: float) -> str:
        return "" if self.unit is None else f" {done:g}/{total:g} {self.unit}"

    def _left(self, done: float, total: float) -> str:
        """", about N s left" from the pace so far, while the work is under way."""
        if not 0 < done < total:
            return ""
        left = (self._clock() - self._started) / done * (total - done)
        return f", about {_duration(left)} left"


def _is_terminal(stream: TextIO) -> bool:
    isatty = getattr(stream, "isatty", None)
    return bool(isatty()) if isatty is not None else False


def _percent(done: float, total: float) -> int:
    return int(100 * min(max(done / total, 0.0), 1.0))


def _duration(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"
