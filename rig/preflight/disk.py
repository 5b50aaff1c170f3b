"""The disk's pre-flight check: room where the run is written for its film at the camera's rate for
the planned duration (MJPEG frames the size of one filmed now), with a margin for the logs."""

from __future__ import annotations

import shutil
from pathlib import Path

from rig.preflight.rows import FAIL, PASS, WARN, CheckRow

MARGIN = 1.25
"""The film's estimate times this: frames vary in size, and the run's logs and plots need room too."""
WARN_BELOW = 2.0
"""Less free room than this many runs' worth: the next run may not fit."""


def check_disk(folder: Path, fps: float | None, frame_bytes: int | None, duration_s: float) -> CheckRow:
    """Whether the disk of `folder` (one that exists) holds a film of `duration_s` at `fps` frames of
    `frame_bytes` (None: no camera, or it gave no frame: the run writes only its logs, estimated as
    nothing)."""
    free = shutil.disk_usage(folder).free
    film = (fps or 0.0) * (frame_bytes or 0) * duration_s
    needed = film * MARGIN
    values = {"folder": str(folder), "free_bytes": free, "needed_bytes": needed, "duration_s": duration_s}
    what = f"{duration_s:g} s at {fps:g} fps, {frame_bytes / 1e3:.0f} kB a frame" if film else "no film"
    measured = f"{_size(free)} free in {folder}; the run needs about {_size(needed)} ({what})"
    if free < needed:
        return CheckRow("disk", "room for the film", FAIL, measured, "free some room, write the run elsewhere (--out), or plan a shorter run", values)
    if free < WARN_BELOW * needed:
        return CheckRow("disk", "room for the film", WARN, measured, "room for this run only: free some before the next", values)
    return CheckRow("disk", "room for the film", PASS, measured, values=values)


def _size(size: float) -> str:
    return f"{size / 1e9:.1f} GB" if size >= 1e9 else f"{size / 1e6:.0f} MB"
