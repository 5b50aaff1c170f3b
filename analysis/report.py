"""Writing tracks to CSV: row by row while they are measured, then once more with the final times.

While the video is tracked every frame's row goes to the file at once (flushed every
FLUSH_EVERY rows), so an analysis that fails or is interrupted keeps what it measured; those rows
carry the time stamp the source recorded. When the analysis has decided the frame times (see
``analysis.timing``) the file is replaced by the final table, whose ``t`` column is those times and
whose valid flags drop the frames the analysis left out (repeated or cut-off blobs).
"""

from __future__ import annotations

import csv
import math
import os
from pathlib import Path
from types import TracebackType

from analysis.errors import AnalysisError
from analysis.tracking import Detection, Track

COLUMNS = ("led_x", "led_y", "led_valid", "sphere_x", "sphere_y", "sphere_valid", "led_peak", "sphere_peak")
STREAM_HEADER = ("frame", "stamp_s", *COLUMNS)
TRACKS_CSV_HEADER = ("frame", "t", *COLUMNS)
FLUSH_EVERY = 64


def _number(value: float, digits: int = 4) -> str:
    """A number for CSV; empty where there is none (NaN)."""
    return "" if math.isnan(value) else f"{value:.{digits}f}"


def _row(frame: int, time: str, led: tuple[float, float, bool, float], sphere: tuple[float, float, bool, float]) -> list[str]:
    return [
        str(frame), time,
        _number(led[0]), _number(led[1]), str(int(led[2])),
        _number(sphere[0]), _number(sphere[1]), str(int(sphere[2])),
        _number(led[3], 1), _number(sphere[3], 1),
    ]  # fmt: skip


def _open(path: Path):
    try:
        return path.open("w", newline="")
    except OSError as error:
        raise AnalysisError(f"cannot write the tracks CSV {path}: {error}") from error


class TrackStream:
    """Appends one row per tracked frame to a CSV file as the frames are tracked."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self._file = _open(self.path)
        self._writer = csv.writer(self._file)
        self._writer.writerow(STREAM_HEADER)
        self._rows = 0

    def write(self, frame: int, stamp: float, led: Detection, sphere: Detection) -> None:
        self._writer.writerow(
            _row(
                frame,
                _number(stamp, 6),
                (led.x, led.y, led.valid, led.peak),
                (sphere.x, sphere.y, sphere.valid, sphere.peak),
            )
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


def write_tracks_csv(path: str | Path, led: Track, sphere: Track) -> None:
    """Write both tracks, one row per frame: final time in s, positions in px, validity as 0/1.

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
                    f"{led.t[i]:.6f}",
                    (led.x[i], led.y[i], bool(led.valid[i]), float(led.peak[i])),
                    (sphere.x[i], sphere.y[i], bool(sphere.valid[i]), float(sphere.peak[i])),
                )
            )
    os.replace(partial, path)

