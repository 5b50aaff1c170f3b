"""The files a live run writes beside those of any run (`rig.session.run_record`), by name, and
reading them back: a file's numeric columns, the camera's instants, images joined to their poses."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from rig.session.run_record import FRAMES_FILE

LIVE_FILE = "live.json"
PUBLISHED_FILE = "published_poses.csv"
SWAPS_FILE = "display_swaps.csv"
MARKERS_FILE = "renderer_markers.csv"


def read_columns(path: Path) -> dict[str, np.ndarray] | None:
    """A CSV run file's numeric columns (empty cells NaN); None where the run did not write it."""
    if not path.is_file():
        return None
    with path.open(encoding="utf-8", newline="") as stream:
        reader = csv.DictReader(stream)
        rows = list(reader)
        names = reader.fieldnames or []

    def number(cell: str | None) -> float:
        try:
            return float(cell) if cell not in ("", None) else np.nan
        except ValueError:
            return np.nan

    return {name: np.array([number(row.get(name)) for row in rows], dtype=np.float64) for name in names}


def camera_instants(out_dir: Path, *, dropped: bool) -> np.ndarray:
    """When the camera took each frame it delivered, or with `dropped` when it should have taken each
    frame it dropped (the film's stand-ins); none where the run had no camera."""
    frames = read_columns(Path(out_dir) / FRAMES_FILE)
    if frames is None:
        return np.array([])
    return frames["t_capture"][frames["filled"] == (1.0 if dropped else 0.0)]


def with_poses(images: np.ndarray, new: np.ndarray, poses: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The rows of `images` (published frame numbers) that are `new` and whose pose was published,
    and the rows of `poses` (published_poses.csv) holding those poses."""
    index = {int(frame): i for i, frame in enumerate(poses["frame"])}
    rows = [(i, index[int(image)]) for i, image in enumerate(images) if new[i] and int(image) in index]
    return np.array([r[0] for r in rows], dtype=int), np.array([r[1] for r in rows], dtype=int)
