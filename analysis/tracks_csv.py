"""The tracks CSV: one format, written row by row while tracking, then once more with the final times.

Every file has the header TRACKS_CSV_HEADER: the frame's number, the time stamp the source recorded
(``stamp_s``), the frame time the analysis decided (``t``), then both blobs' positions in px,
validity as 0/1 and peaks. While the video is tracked every frame's row goes to the file at once
(flushed every FLUSH_EVERY rows), so an analysis that fails or is interrupted keeps what it
measured: those rows hold the detections as measured, and ``t`` is empty because the frame times
are decided from all the stamps (see ``analysis.timing``). Then the file is replaced by the final
table, whose ``t`` is filled in and whose valid flags drop the frames the analysis left out
(repeated frames). An empty cell is a value there is none of.
"""

from __future__ import annotations

import csv
import math
import os
from pathlib import Path
from types import TracebackType
from typing import TextIO

import numpy as np

from analysis.errors import AnalysisError
from analysis.blobs import Detection, Track

TRACKS_CSV_HEADER = (
    "frame", "stamp_s", "t",
    "led_x", "led_y", "led_valid", "sphere_x", "sphere_y", "sphere_valid", "led_peak", "sphere_peak",
)  # fmt: skip
FLUSH_EVERY = 64


def _number(value: float, digits: int = 4) -> str:
    """A number for CSV; empty where there is none (NaN)."""
    return "" if math.isnan(value) else f"{value:.{digits}f}"


def _row(
    frame: int, stamp: float, time: float, led: tuple[float, float, bool, float], sphere: tuple[float, float, bool, float]
) -> list[str]:
    return [
        str(frame), _number(stamp, 6), _number(time, 6),
        _number(led[0]), _number(led[1]), str(int(led[2])),
        _number(sphere[0]), _number(sphere[1]), str(int(sphere[2])),
        _number(led[3], 1), _number(sphere[3], 1),
    ]  # fmt: skip


def _open(path: Path) -> TextIO:
    try:
        return path.open("w", newline="")
    except OSError as error:
        raise AnalysisError(f"cannot write the tracks CSV {path}: {error}") from error


class TrackStream:
    """Appends one row per tracked frame to a CSV file as the frames are tracked (``t`` left empty)."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self._file = _open(self.path)
        self._writer = csv.writer(self._file)
        self._writer.writerow(TRACKS_CSV_HEADER)
        self._rows = 0

    def write(self, frame: int, stamp: float, led: Detection, sphere: Detection) -> None:
        self._writer.writerow(
            _row(frame, stamp, math.nan, (led.x, led.y, led.valid, led.peak), (sphere.x, sphere.y, sphere.valid, sphere.peak))
        )
        self._rows += 1
        if self._rows % FLUSH_EVERY == 0:
            self._file.flush()

    def close(self) -> None:
        self._file.close()

    def __enter__(self) -> TrackStream:
        return self

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None) -> None:
        self.close()


def write_tracks_csv(path: str | Path, stamps: np.ndarray, led: Track, sphere: Track) -> None:
    """Write both tracks, one row per frame, with the times the source stamped (``stamps``) and the
    final frame times (the LED track's).

    The file is written beside its destination and then moved over it, so a reader never sees a
    half-written table.
    """
    path = Path(path)
    partial = path.with_name(path.name + ".partial")
    with _open(partial) as stream:
        writer = csv.writer(stream)
        writer.writerow(TRACKS_CSV_HEADER)
        for i in range(led.t.size):
            writer.writerow(
                _row(
                    i,
                    float(stamps[i]),
                    float(led.t[i]),
                    (led.x[i], led.y[i], bool(led.valid[i]), float(led.peak[i])),
                    (sphere.x[i], sphere.y[i], bool(sphere.valid[i]), float(sphere.peak[i])),
                )
            )
    os.replace(partial, path)
