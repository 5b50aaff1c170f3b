"""How the rig writes what a run records, as the run goes: tables as CSV, camera frames as video.

Every table a run records (tracker samples, application and display frames, a board's events) is a
`CsvRecord`. Rows reach the operating system as they are written (each row, or each batch where
the caller says when a batch ends), so a crash or a Ctrl-C leaves a readable file holding every
row written so far: a partial file and a finished one have the same header and the same rows. A
power cut may still lose the last rows: rows are flushed, not fsynced.

Floats are written with `repr`, so reading a file back gives the exact values; None is an empty
cell. Lines end in a bare newline.

A `VideoRecord` is released on any exit (use it as a context manager), so an interrupted run
keeps a playable video of every frame written. Each frame's write is checked, and the frames the
file holds are counted back when it is closed: a frame the film does not hold raises RigError,
never a film shorter than its frame table.
"""

from __future__ import annotations

import csv
import os
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from rig.errors import RigError


def _cell(value: Any) -> Any:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(float(value))
    return value


class CsvRecord:
    """A CSV table written as it grows.

    flush_each_row False leaves flushing to the caller (`flush()` after each batch of rows), for
    sources that deliver many rows at once. An existing file is replaced only with overwrite=True.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        header: Sequence[str],
        *,
        overwrite: bool = False,
        flush_each_row: bool = True,
    ) -> None:
        self.path = Path(path)
        self.header = tuple(header)
        self._flush_each_row = flush_each_row
        try:
            self._file = open(self.path, "w" if overwrite else "x", encoding="utf-8", newline="")
        except FileExistsError:
            raise RigError(f"{self.path} already exists; choose another folder or pass --overwrite") from None
        except OSError as error:
            raise RigError(f"cannot write {self.path}: {error.strerror}") from None
        self._writer = csv.writer(self._file, lineterminator="\n")
        self._writer.writerow(self.header)
        self._file.flush()
        self.rows = 0

    def write(self, row: Sequence[Any]) -> None:
        """Append one row (as many cells as the header has)."""
        if len(row) != len(self.header):
            raise ValueError(f"{self.path.name}: a row of {len(row)} cells for a header of {len(self.header)}")
        self._writer.writerow([_cell(value) for value in row])
        self.rows += 1
        if self._flush_each_row:
            self._file.flush()

    def write_numbers(self, rows: Sequence[Sequence[float | int | None]]) -> None:
        """Append rows of numbers and blanks (None), written as `write` writes them: the fast path
        for a tracker's thousand rows a second, where the csv module's per-cell work would cost more
        than reading the tracker (numbers need no quoting)."""
        width = len(self.header)
        lines = []
        for row in rows:
            if len(row) != width:
                raise ValueError(f"{self.path.name}: a row of {len(row)} cells for a header of {width}")
            lines.append(",".join([repr(v) if type(v) is float else "" if v is None else str(_cell(v)) for v in row]))
        if lines:
            self._file.write("\n".join(lines) + "\n")
        self.rows += len(lines)
        if self._flush_each_row:
            self._file.flush()

    def flush(self) -> None:
        self._file.flush()

    def close(self) -> None:
        self._file.close()

    def __enter__(self) -> CsvRecord:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


MJPEG_AVI_MAX_FPS = 1000.0
"""The fastest MJPEG AVI written here: above it FFmpeg's AVI muxer (through OpenCV) keeps a coarser
time base (1/600 s), puts frames on the same tick and refuses them."""


def check_avi_rate(fps: float, advice: str = "") -> None:
    """RigError unless an MJPEG AVI (`VideoRecord`) holds `fps` frames a second; `advice` says what
    else the caller may film in."""
    if not fps <= MJPEG_AVI_MAX_FPS:
        raise RigError(
            f"an MJPEG AVI film holds at most {MJPEG_AVI_MAX_FPS:g} frames a second, not {fps:g}: "
            f"film at {MJPEG_AVI_MAX_FPS:g} fps or fewer{advice}"
        )


def avi_frame_count(path: Path) -> int:
    """The frames an AVI's index holds, as a reader finds them."""
    import cv2  # here, not above: a run's tables are written without OpenCV

    capture = cv2.VideoCapture(str(path))
    try:
        return max(int(capture.get(cv2.CAP_PROP_FRAME_COUNT)), 0) if capture.isOpened() else 0
    finally:
        capture.release()


class VideoRecord:
    """Writes 8-bit grey frames to an MJPEG AVI: a codec every OpenCV build reads back.

    A rate the AVI cannot hold (`check_avi_rate`) is refused before the first frame. A frame that
    cannot be written (a full disk) raises RigError; the film then holds, playable, the `frames`
    written before it. Closing counts the file's frames back and raises RigError unless it holds
    every frame written.
    """

    FOURCC = "MJPG"
    QUALITY = 95

    def __init__(self, path: str | os.PathLike[str], fps: float, width: int, height: int) -> None:
        import cv2

        check_avi_rate(fps)
        self.path = Path(path)
        self._writer: cv2.VideoWriter | None = cv2.VideoWriter(
            str(self.path), cv2.VideoWriter_fourcc(*self.FOURCC), fps, (width, height), True
        )
        if not self._writer.isOpened():
            raise RigError(f"cannot write video {self.path}: OpenCV has no {self.FOURCC} writer here")
        self._writer.set(cv2.VIDEOWRITER_PROP_QUALITY, self.QUALITY)
        self.frames = 0

    def write(self, grey: np.ndarray, t_start: float | None = None) -> None:
        """Append a frame; an AVI places frame i at i / fps, so its start time is not stored (taken
        so that every film writer takes the same frames, `rig.film_file`)."""
        if self._writer is None:
            raise RigError(f"the film {self.path} is closed; frame {self.frames} cannot be added")
        import cv2

        if not self._writer.write(cv2.cvtColor(grey, cv2.COLOR_GRAY2BGR)):
            raise RigError(
                f"frame {self.frames} could not be written to {self.path} (is the disk full?); "
                f"the film holds the {self.frames} before it"
            )
        self.frames += 1

    def close(self) -> None:
        """Release the file and count its frames back (RigError unless it holds every frame written);
        safe to call more than once."""
        writer, self._writer = self._writer, None
        if writer is None:
            return
        writer.release()
        held = avi_frame_count(self.path)
        if held != self.frames:
            raise RigError(f"{self.path} holds {held} of the {self.frames} frames written to it; check the disk and film again")

    def __enter__(self) -> VideoRecord:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
