"""Frames held in memory, as a numpy array."""

from __future__ import annotations

from collections.abc import Generator, Iterator

import cv2
import numpy as np

from analysis.errors import AnalysisError
from analysis.video.frames import Crop, Frame, Repeats, checked_every, checked_fps, cut_frames, noted_repeats


class FrameArray:
    """Frames held in memory: (N, H, W) grey or (N, H, W, 3) BGR, any real dtype; frame i at i / fps."""

    def __init__(self, frames: np.ndarray, fps: float | None) -> None:
        if frames.ndim not in (3, 4) or (frames.ndim == 4 and frames.shape[3] != 3):
            raise AnalysisError(
                f"an array of frames must have shape (N, H, W) or (N, H, W, 3), not {frames.shape}"
            )
        if frames.shape[0] == 0 or frames.shape[1] == 0 or frames.shape[2] == 0:
            raise AnalysisError("the array of frames is empty; give at least a few pendulum periods of video")
        if not np.issubdtype(frames.dtype, np.number) or np.iscomplexobj(frames):
            raise AnalysisError(f"frames must hold real pixel values, not {frames.dtype}")
        checked = checked_fps(fps)
        if checked is None:
            raise AnalysisError("no frame rate is known for an array of frames; pass fps=<frames per second>")
        self._frames = frames
        self._fps = checked

    @property
    def fps(self) -> float:
        return self._fps

    @property
    def container_fps(self) -> None:
        return None

    @property
    def frame_size(self) -> tuple[int, int]:
        return int(self._frames.shape[2]), int(self._frames.shape[1])

    @property
    def frame_count(self) -> int:
        return int(self._frames.shape[0])

    @property
    def name(self) -> str:
        return "the array of frames"

    @property
    def stamp_origin(self) -> str:
        return "array index"

    @property
    def decodes_in_part(self) -> bool:
        return False

    def frames(self, crop: Crop | None = None, every: int = 1, repeats: Repeats | None = None) -> Iterator[Frame]:
        every = checked_every(every)
        return cut_frames(noted_repeats(self._grey_frames(every), repeats, every), crop)

    def _grey_frames(self, every: int) -> Generator[Frame, None, None]:
        dtype = np.uint8 if self._frames.dtype == np.uint8 else np.float32
        for index in range(0, len(self._frames), every):
            grey = self._frames[index].astype(dtype, copy=False)
            yield index / self._fps, cv2.cvtColor(grey, cv2.COLOR_BGR2GRAY) if grey.ndim == 3 else grey
