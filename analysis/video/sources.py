"""The frame source for what a user gives: a video file, a folder of numbered images, or an array."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from analysis.errors import AnalysisError
from analysis.video.array import FrameArray
from analysis.video.file import VideoFile
from analysis.video.frames import FrameSource
from analysis.video.images import ImageFolder


def open_frames(source: str | Path | np.ndarray, fps: float | None = None) -> FrameSource:
    """A frame source for a video path, a folder of numbered images, or a (N, H, W) / (N, H, W, 3)
    BGR array of frames; ``fps`` overrides the file's frame rate and is required for the others."""
    if isinstance(source, np.ndarray):
        return FrameArray(source, fps)
    if isinstance(source, (str, Path)):
        path = Path(source)
        return ImageFolder(path, fps) if path.is_dir() else VideoFile(path, fps)
    raise AnalysisError(
        f"cannot analyse a {type(source).__name__}; give a video file, a folder of images or a numpy array of frames"
    )
