"""What every frame source gives the analyser, and the crop a consumer sets while reading.

Every source yields ``(stamp, frame)`` pairs in order: ``frame`` is 2-D (height, width), uint8 for
files, images and uint8 arrays, float32 for other arrays; ``stamp`` is the frame's time as the
source records it, in seconds (a container's presentation time, an image's number over the frame
rate, an array index over the frame rate), or NaN where there is none. Which times the analysis
trusts is decided afterwards from all the stamps (see ``analysis.timing``).

A consumer that needs only part of each frame (the tracker, once it knows its ROIs) says so with a
``Crop``: every frame yielded after the crop is set holds only that rectangle. One that needs only
a sample of the frames asks for every n-th; a source whose ``decodes_in_part`` is true then skips
the others without decoding them. One that wants to know which frames repeat the one before
exactly, whole (a recorder's copy, which a crop cannot see), passes ``Repeats``: a source reading
every frame notes them there.
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

    def frames(self, crop: Crop | None = None, every: int = 1, repeats: Repeats | None = None) -> Iterator[Frame]:
        """Stamped grey frames in order, or every ``every``-th of them from the first; once ``crop``
        is set, only its rectangle of each. Reading every frame, the source notes in ``repeats``
        each one whose whole image is the one before's exactly."""
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


class Repeats:
    """The frames (indices from the first) whose whole image repeats the frame before exactly, as a
    source reading every frame notes them: an encoded frame that repeats is compared by its bytes
    where they decode to the whole image (Motion-JPEG), else by its decoded pixels."""

    def __init__(self) -> None:
        self.frames: list[int] = []

    def start(self) -> None:
        """Forget what an earlier reading noted: a source starts each reading with this."""
        self.frames.clear()

    def note(self, index: int, same: bool) -> None:
        if same:
            self.frames.append(index)

    def mask(self, count: int) -> np.ndarray:
        """The repeats as a bool per frame, for ``count`` frames."""
        mask = np.zeros(count, dtype=bool)
        mask[[i for i in self.frames if i < count]] = True
        return mask


def same_image(image: np.ndarray, previous: np.ndarray | None) -> bool:
    """Whether two whole images (or encoded frames' bytes) are identical."""
    return previous is not None and image.shape == previous.shape and bool(np.array_equal(image, previous))


def noted_repeats(frames: Generator[Frame, None, None], repeats: Repeats | None, every: int) -> Generator[Frame, None, None]:
    """Whole frames as they are, each compared with the one before and noted in ``repeats``
    (reading every frame; a sample notes nothing). Closing this closes ``frames``."""
    if repeats is None or every != 1:
        yield from frames
        return
    repeats.start()
    previous = None
    with contextlib.closing(frames):
        for index, (stamp, image) in enumerate(frames):
            repeats.note(index, same_image(image, previous))
            previous = image
            yield stamp, image


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
