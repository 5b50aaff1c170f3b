"""What every frame source gives the analyser, and the crop a consumer sets while reading.

Every source yields ``(stamp, frame)`` pairs in order: ``frame`` is 2-D (height, width), uint8 for
files, images and uint8 arrays, float32 for other arrays; ``stamp`` is the frame's time as the
source records it, in seconds (a container's presentation time, an image's number over the frame
rate, an array index over the frame rate), or NaN where there is none. Which times the analysis
trusts is decided afterwards from all the stamps (see ``analysis.timing``).

A consumer that needs only part of each frame (the tracker, once it knows its ROIs) says so with a
``Crop``: every frame yielded after the crop is set holds only that rectangle. One that needs only
a sample of the frames asks for every n-th; a source whose ``decodes_in_part`` is true then skips
the others without decoding them.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Generator, Iterator
from typing import Protocol

import numpy as np

from analysis.errors import AnalysisError

Frame = tuple[float, np.ndarray]


class FrameSource(Protocol):
    """What the analyser needs from a video: its rate, size, length and grey frames in order."""

    @property
    def fps(self) -> float | None:
        """The frame rate the user gave, else the container's if plausible, else None."""
        ...

    @property
    def container_fps(self) -> float | None:
        """The frame rate the file states (None for arrays and image folders)."""
        ...

    @property
    def frame_size(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        ...

    @property
    def frame_count(self) -> int:
        """Number of frames; for a file, what its container says (used for progress and checks)."""
        ...

    @property
    def name(self) -> str: ...

    @property
    def stamp_origin(self) -> str:
        """Where the frames' stamps come from, for messages."""
        ...

    @property
    def decodes_in_part(self) -> bool:
        """Whether frames left out (``every``) cost nothing to skip and a crop's rectangle is decoded
        alone, so that reading a sample of frames, then the video again in rectangles, is cheaper
        than decoding the frames whole."""
        ...

    def frames(self, crop: Crop | None = None, every: int = 1) -> Iterator[Frame]:
        """Stamped grey frames in order, or every ``every``-th of them from the first; once ``crop``
        is set, only its rectangle of each."""
        ...


class Crop:
    """The rectangle of each frame a consumer still needs, which it may set while reading frames.

    Unset, frames are whole. Once set (``to``), every frame yielded afterwards is that rectangle:
    a source that can decode part of a frame decodes only the rectangle, and any frame decoded
    whole before the crop was set (the read-ahead) is cut to it on the way out.
    """

    def __init__(self) -> None:
        # (rows, columns) as slices, set in one assignment: decoding threads read it.
        self.region: tuple[slice, slice] | None = None

    def to(self, rows: slice, cols: slice) -> None:
        """Keep rows ``rows`` and columns ``cols`` (slices with a start and a stop) of every frame."""
        self.region = (rows, cols)

    def cut(self, frame: np.ndarray) -> np.ndarray:
        """The rectangle of a whole frame (a view); a frame already the rectangle's size is returned as it is."""
        if self.region is None:
            return frame
        rows, cols = self.region
        if frame.shape == (rows.stop - rows.start, cols.stop - cols.start):
            return frame
        return frame[rows, cols]


def cut_frames(frames: Generator[Frame, None, None], crop: Crop | None) -> Iterator[Frame]:
    """The frames, each cut to the crop once it is set; closing this closes ``frames``."""
    with contextlib.closing(frames):
        for stamp, frame in frames:
            yield stamp, frame if crop is None else crop.cut(frame)


def checked_every(every: int) -> int:
    """``every`` as given; ValueError unless it is a positive number of frames."""
    if every < 1:
        raise ValueError(f"every must be a positive number of frames, not {every}")
    return every


def checked_fps(fps: float | None) -> float | None:
    """A user's frame rate as a float; AnalysisError unless it is a positive finite number."""
    if fps is None:
        return None
    value = float(fps)
    if not math.isfinite(value) or value <= 0:
        raise AnalysisError(f"frame rate {fps!r} is not a positive number of frames per second")
    return value
