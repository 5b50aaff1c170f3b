"""Frame sources: a video file or an in-memory array, yielding grayscale frames in order.

Every source yields 2-D frames (height, width): uint8 for video files and uint8 arrays, float32 for
other arrays. Frame ``i`` was taken at ``t = i / fps``.

Motion-JPEG files are read as raw packets and decoded straight to grayscale with ``cv2.imdecode``:
libjpeg then skips chroma upsampling and colour conversion, which makes decoding about 1.7x faster
than ``VideoCapture.read`` followed by a grey conversion, and lets a few threads decode ahead of the
tracker. Any other codec, or a Motion-JPEG stream whose packets are not complete JPEG images, is
read the ordinary way.
"""

from __future__ import annotations

import math
import os
from collections import deque
from collections.abc import Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from typing import Protocol

import cv2
import numpy as np

from analysis.errors import AnalysisError

# Threads decoding JPEG frames (OpenCV releases the GIL while decoding), and how many frames they
# may run ahead of the consumer.
DECODE_THREADS = min(4, os.cpu_count() or 1)
READ_AHEAD = 2 * DECODE_THREADS


class FrameSource(Protocol):
    """What the analyser needs from a video: its rate, size, length and grey frames in order."""

    @property
    def fps(self) -> float: ...

    @property
    def frame_size(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        ...

    @property
    def frame_count(self) -> int:
        """Number of frames; for a file, what its container says (used for progress only)."""
        ...

    def frames(self) -> Iterator[np.ndarray]: ...


def open_frames(source: str | Path | np.ndarray, fps: float | None = None) -> FrameSource:
    """A frame source for a video path or a (N, H, W) / (N, H, W, 3) BGR array of frames."""
    if isinstance(source, np.ndarray):
        return FrameArray(source, fps)
    if isinstance(source, (str, Path)):
        return VideoFile(source, fps)
    raise AnalysisError(
        f"cannot analyse a {type(source).__name__}; give a video file path or a numpy array of frames"
    )


def _checked_fps(fps: float | None) -> float | None:
    if fps is None:
        return None
    value = float(fps)
    if not math.isfinite(value) or value <= 0:
        raise AnalysisError(f"frame rate {fps!r} is not a positive number of frames per second")
    return value


class FrameArray:
    """Frames held in memory: (N, H, W) grey or (N, H, W, 3) BGR, any real dtype."""

    def __init__(self, frames: np.ndarray, fps: float | None) -> None:
        if frames.ndim not in (3, 4) or (frames.ndim == 4 and frames.shape[3] != 3):
            raise AnalysisError(
                f"an array of frames must have shape (N, H, W) or (N, H, W, 3), not {frames.shape}"
            )
        if frames.shape[0] == 0 or frames.shape[1] == 0 or frames.shape[2] == 0:
            raise AnalysisError("the array of frames is empty; give at least a few pendulum periods of video")
        if not np.issubdtype(frames.dtype, np.number) or np.iscomplexobj(frames):
            raise AnalysisError(f"frames must hold real pixel values, not {frames.dtype}")
        checked = _checked_fps(fps)
        if checked is None:
            raise AnalysisError("an array of frames carries no frame rate; pass fps=<frames per second>")
        self._frames = frames
        self._fps = checked

    @property
    def fps(self) -> float:
        return self._fps

    @property
    def frame_size(self) -> tuple[int, int]:
        return int(self._frames.shape[2]), int(self._frames.shape[1])

    @property
    def frame_count(self) -> int:
        return int(self._frames.shape[0])

    def frames(self) -> Iterator[np.ndarray]:
        dtype = np.uint8 if self._frames.dtype == np.uint8 else np.float32
        for frame in self._frames:
            grey = frame.astype(dtype, copy=False)
            yield cv2.cvtColor(grey, cv2.COLOR_BGR2GRAY) if grey.ndim == 3 else grey


class VideoFile:
    """A video file read with OpenCV; the frame rate comes from ``fps`` if given, else the container."""

    def __init__(self, path: str | Path, fps: float | None = None) -> None:
        self._path = Path(path)
        if not self._path.is_file():
            raise AnalysisError(f"video file {self._path} does not exist; check the path")
        capture = cv2.VideoCapture(str(self._path))
        try:
            if not capture.isOpened():
                raise AnalysisError(
                    f"{self._path} cannot be read as a video; give a video file (e.g. an MJPG .avi)"
                )
            container_fps = capture.get(cv2.CAP_PROP_FPS)
            self._frame_count = max(int(capture.get(cv2.CAP_PROP_FRAME_COUNT)), 0)
            fourcc = int(capture.get(cv2.CAP_PROP_FOURCC)).to_bytes(4, "little")
            ok, first = capture.read()
        finally:
            capture.release()
        if not ok:
            raise AnalysisError(f"{self._path} contains no frames; record the pendulum for a few periods")
        explicit = _checked_fps(fps)
        if explicit is None and not (math.isfinite(container_fps) and container_fps > 0):
            raise AnalysisError(f"{self._path} does not say its frame rate; pass fps=<frames per second>")
        self._fps = explicit if explicit is not None else float(container_fps)
        self._frame_size = int(first.shape[1]), int(first.shape[0])
        self._raw_jpeg = fourcc.upper() == b"MJPG" and self._raw_packets_decode()

    @property
    def fps(self) -> float:
        return self._fps

    @property
    def frame_size(self) -> tuple[int, int]:
        return self._frame_size

    @property
    def frame_count(self) -> int:
        return self._frame_count

    def _raw_packets_decode(self) -> bool:
        """Whether this file's packets are whole JPEG images of the frame size (see module docstring)."""
        capture = cv2.VideoCapture(str(self._path))
        try:
            if not capture.set(cv2.CAP_PROP_FORMAT, -1):
                return False
            ok, packet = capture.read()
        finally:
            capture.release()
        if not ok or packet is None or packet.dtype != np.uint8:
            return False
        grey = cv2.imdecode(packet.reshape(-1), cv2.IMREAD_GRAYSCALE)
        return grey is not None and (grey.shape[1], grey.shape[0]) == self._frame_size

    def frames(self) -> Iterator[np.ndarray]:
        capture = cv2.VideoCapture(str(self._path))
        try:
            if self._raw_jpeg and capture.set(cv2.CAP_PROP_FORMAT, -1):
                yield from self._decoded_packets(capture)
                return
            while True:
                ok, frame = capture.read()
                if not ok:
                    return
                yield cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY) if frame.ndim == 3 else frame
        finally:
            capture.release()

    def _decoded_packets(self, capture: cv2.VideoCapture) -> Iterator[np.ndarray]:
        """JPEG packets decoded to grey by worker threads a few frames ahead of the consumer, in order."""
        with ThreadPoolExecutor(max_workers=DECODE_THREADS) as pool:
            pending: deque[Future[np.ndarray | None]] = deque()
            index = 0
            more = True
            while more or pending:
                if more:
                    more, packet = capture.read()
                    if more:
                        pending.append(
                            pool.submit(cv2.imdecode, packet.reshape(-1).copy(), cv2.IMREAD_GRAYSCALE)
                        )
                if pending and (not more or len(pending) > READ_AHEAD):
                    grey = pending.popleft().result()
                    if grey is None:
                        raise AnalysisError(
                            f"frame {index} of {self._path} is corrupt; re-record or trim the video"
                        )
                    yield grey
                    index += 1
