"""Frame sources: a video file, a folder of numbered images, or an in-memory array.

Every source yields ``(stamp, frame)`` pairs in order: ``frame`` is 2-D (height, width), uint8 for
files, images and uint8 arrays, float32 for other arrays; ``stamp`` is the frame's time as the
source records it, in seconds (a container's presentation time, an image's number over the frame
rate, an array index over the frame rate), or NaN where there is none. Which times the analysis
trusts is decided afterwards from all the stamps (see ``analysis.timing``).

A consumer that needs only part of each frame (the tracker, once it knows its ROIs) says so with a
``Crop``: every frame yielded after the crop is set holds only that rectangle. One that needs only
a sample of the frames asks for every n-th; a source whose ``decodes_in_part`` is true then skips
the others without decoding them.

Motion-JPEG files are read as raw packets and decoded straight to grayscale with ``cv2.imdecode``:
libjpeg then skips chroma upsampling and colour conversion, which makes decoding about 1.7x faster
than ``VideoCapture.read`` followed by a grey conversion. Once a crop is set, a packet is decoded
only as far as the crop needs (``analysis._jpeg_region``): the tracking then costs less than the
decoding it saves (``rig bench analyser`` compares the analysis with decoding whole frames alone).
Packets and image files are decoded a few frames ahead of the tracker by a few threads, the
tracker's own among them (OpenCV and the region decoder release the GIL while decoding). Any other
codec is read the ordinary way and cropped afterwards.
"""

from __future__ import annotations

import contextlib
import itertools
import math
import os
import re
from collections import deque
from collections.abc import Callable, Generator, Iterable, Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Generic, Protocol, TypeVar

import cv2
import numpy as np

from analysis._jpeg_region import decode_grey
from analysis.errors import AnalysisError

# Threads decoding frames, the consumer's among them, and how many frames they may run ahead of the
# consumer (enough to keep them busy while the consumer finds the ROIs in the first frames).
DECODE_THREADS = min(4, os.cpu_count() or 1)
READ_AHEAD = 64
# Frames handed to a thread at a time: threads exchange work once per batch, not once per frame.
DECODE_BATCH = 8
IMAGE_SUFFIXES = frozenset({".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm", ".webp"})
# Frame rates outside this range are not believed when a container states them.
PLAUSIBLE_FPS = (1.0, 10_000.0)

Frame = tuple[float, np.ndarray]
_Item = TypeVar("_Item")


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


def _cut(frames: Generator[Frame, None, None], crop: Crop | None) -> Iterator[Frame]:
    with contextlib.closing(frames):
        for stamp, frame in frames:
            yield stamp, frame if crop is None else crop.cut(frame)


def _checked_every(every: int) -> int:
    if every < 1:
        raise ValueError(f"every must be a positive number of frames, not {every}")
    return every


def _decode_jpeg(packet: np.ndarray, crop: Crop | None) -> np.ndarray | None:
    """A grey frame from one JPEG packet: only the crop's rectangle once it is set (see ``Crop``),
    else the whole frame; None if it cannot be decoded."""
    region = crop.region if crop is not None else None
    if region is not None:
        rows, cols = region
        rectangle = np.empty((rows.stop - rows.start, cols.stop - cols.start), dtype=np.uint8)
        if decode_grey(packet, rows.start, cols.start, rectangle, *rectangle.shape):
            return rectangle
    return cv2.imdecode(packet, cv2.IMREAD_GRAYSCALE)


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


def checked_fps(fps: float | None) -> float | None:
    """A user's frame rate as a float; AnalysisError unless it is a positive finite number."""
    if fps is None:
        return None
    value = float(fps)
    if not math.isfinite(value) or value <= 0:
        raise AnalysisError(f"frame rate {fps!r} is not a positive number of frames per second")
    return value


@dataclass
class _Batch(Generic[_Item]):
    """Consecutive items, the worker's task mapping them, and their results if the consumer mapped them."""

    items: list[_Item]
    task: Future[list[np.ndarray | None]]
    results: list[np.ndarray | None] | None = None


def _ordered_map(
    function: Callable[[_Item], np.ndarray | None], items: Iterable[_Item], describe: Callable[[int], str]
) -> Iterator[np.ndarray]:
    """function(item) for each item, computed a few items ahead, yielded in order.

    Items are handed to worker threads DECODE_BATCH at a time. The consumer maps items too: while
    the batch it needs next is still being mapped, it takes the earliest batch that no worker has
    started and maps it itself. So no core idles while the consumer works on a frame (tracking),
    and no more threads compete for the cores than there are (an extra one would be preempted
    while it holds the GIL, stalling the others).
    A None result is a frame that cannot be decoded: AnalysisError naming it via ``describe``.
    """

    def run(batch: list[_Item]) -> list[np.ndarray | None]:
        return [function(item) for item in batch]

    iterator = iter(items)
    batches = iter(lambda: list(itertools.islice(iterator, DECODE_BATCH)), [])
    pending: deque[_Batch[_Item]] = deque()
    pool = ThreadPoolExecutor(max_workers=max(1, DECODE_THREADS - 1))
    try:
        index = 0
        while True:
            while len(pending) * DECODE_BATCH < READ_AHEAD and (batch := next(batches, None)) is not None:
                pending.append(_Batch(batch, pool.submit(run, batch)))
            if not pending:
                return
            head = pending[0]
            while head.results is None and not head.task.done():
                unstarted = next((b for b in pending if b.results is None and b.task.cancel()), None)
                if unstarted is None:
                    break
                unstarted.results = run(unstarted.items)
            pending.popleft()
            for frame in head.task.result() if head.results is None else head.results:
                if frame is None:
                    raise AnalysisError(f"{describe(index)} is corrupt; re-record it or leave it out")
                yield frame
                index += 1
    finally:
        pool.shutdown(cancel_futures=True)


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

    def frames(self, crop: Crop | None = None, every: int = 1) -> Iterator[Frame]:
        return _cut(self._grey_frames(_checked_every(every)), crop)

    def _grey_frames(self, every: int) -> Generator[Frame, None, None]:
        dtype = np.uint8 if self._frames.dtype == np.uint8 else np.float32
        for index in range(0, len(self._frames), every):
            grey = self._frames[index].astype(dtype, copy=False)
            yield index / self._fps, cv2.cvtColor(grey, cv2.COLOR_BGR2GRAY) if grey.ndim == 3 else grey


def _frame_number(path: Path) -> int | None:
    numbers = re.findall(r"\d+", path.stem)
    return int(numbers[-1]) if numbers else None


class ImageFolder:
    """A folder of numbered images (frame_0001.png, ...): frame n was taken at n / fps.

    The number is the last run of digits in each file name; gaps in the numbering are dropped
    frames and show as gaps in time.
    """

    def __init__(self, folder: Path, fps: float | None) -> None:
        images = sorted(p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES and p.is_file())
        if not images:
            raise AnalysisError(
                f"{folder} holds no images ({', '.join(sorted(IMAGE_SUFFIXES))}); give a video file or a folder of frames"
            )
        unnumbered = [p.name for p in images if _frame_number(p) is None]
        if unnumbered:
            raise AnalysisError(
                f"{folder} holds images without a frame number, e.g. {unnumbered[0]}; name them like frame_0001.png"
            )
        numbered = sorted((_frame_number(p), p) for p in images)
        repeated = [n for (n, _), (m, _) in zip(numbered, numbered[1:]) if n == m]
        if repeated:
            raise AnalysisError(f"{folder} holds two images numbered {repeated[0]}; keep one image per frame number")
        self._numbers = [n for n, _ in numbered]
        self._paths = [p for _, p in numbered]
        checked = checked_fps(fps)
        if checked is None:
            raise AnalysisError(
                f"no frame rate is known for the images in {folder}; pass --fps (fps=) with the camera's frame rate"
            )
        self._fps = checked
        first = cv2.imread(str(self._paths[0]), cv2.IMREAD_GRAYSCALE)
        if first is None:
            raise AnalysisError(f"{self._paths[0]} cannot be read as an image")
        self._frame_size = int(first.shape[1]), int(first.shape[0])
        self._folder = folder

    @property
    def fps(self) -> float:
        return self._fps

    @property
    def container_fps(self) -> None:
        return None

    @property
    def frame_size(self) -> tuple[int, int]:
        return self._frame_size

    @property
    def frame_count(self) -> int:
        return len(self._paths)

    @property
    def name(self) -> str:
        return str(self._folder)

    @property
    def stamp_origin(self) -> str:
        return "image number"

    @property
    def decodes_in_part(self) -> bool:
        return False

    def frames(self, crop: Crop | None = None, every: int = 1) -> Iterator[Frame]:
        return _cut(self._grey_frames(_checked_every(every)), crop)

    def _grey_frames(self, every: int) -> Generator[Frame, None, None]:
        paths = self._paths[::every]
        decoded = _ordered_map(
            lambda path: cv2.imread(str(path), cv2.IMREAD_GRAYSCALE),
            paths,
            lambda index: f"image {paths[index]}",
        )
        for number, frame in zip(self._numbers[::every], decoded, strict=False):
            if (frame.shape[1], frame.shape[0]) != self._frame_size:
                raise AnalysisError(
                    f"image number {number} in {self._folder} is {frame.shape[1]}x{frame.shape[0]}, not "
                    f"{self._frame_size[0]}x{self._frame_size[1]} like the first; keep one camera's frames per folder"
                )
            yield (number - self._numbers[0]) / self._fps, frame


class VideoFile:
    """A video file read with OpenCV; its frames carry the container's presentation times."""

    def __init__(self, path: str | Path, fps: float | None = None) -> None:
        self._path = Path(path)
        if not self._path.is_file():
            raise AnalysisError(f"video file {self._path} does not exist; check the path")
        capture = cv2.VideoCapture(str(self._path))
        try:
            if not capture.isOpened():
                raise AnalysisError(
                    f"{self._path} cannot be read as a video; give a video file (mp4, avi, mov, mkv) "
                    "or a folder of numbered images"
                )
            stated = capture.get(cv2.CAP_PROP_FPS)
            self._frame_count = max(int(capture.get(cv2.CAP_PROP_FRAME_COUNT)), 0)
            fourcc = int(capture.get(cv2.CAP_PROP_FOURCC)).to_bytes(4, "little")
            ok, first = capture.read()
        finally:
            capture.release()
        if not ok or first is None:
            raise AnalysisError(f"{self._path} contains no frames; record the pendulum for a few periods")
        low, high = PLAUSIBLE_FPS
        self._container_fps = float(stated) if math.isfinite(stated) and low <= stated <= high else None
        explicit = checked_fps(fps)
        self._fps = explicit if explicit is not None else self._container_fps
        self._frame_size = int(first.shape[1]), int(first.shape[0])
        self._raw_jpeg = fourcc.upper() == b"MJPG" and self._raw_packets_decode()

    @property
    def fps(self) -> float | None:
        return self._fps

    @property
    def container_fps(self) -> float | None:
        return self._container_fps

    @property
    def frame_size(self) -> tuple[int, int]:
        return self._frame_size

    @property
    def frame_count(self) -> int:
        return self._frame_count

    @property
    def name(self) -> str:
        return str(self._path)

    @property
    def stamp_origin(self) -> str:
        return "container"

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

    @property
    def decodes_in_part(self) -> bool:
        """True for Motion-JPEG: a packet left out is never decoded, and a crop is decoded alone."""
        return self._raw_jpeg

    def frames(self, crop: Crop | None = None, every: int = 1) -> Iterator[Frame]:
        return _cut(self._grey_frames(crop, _checked_every(every)), crop)

    def _grey_frames(self, crop: Crop | None, every: int) -> Generator[Frame, None, None]:
        capture = cv2.VideoCapture(str(self._path))
        try:
            if self._raw_jpeg and capture.set(cv2.CAP_PROP_FORMAT, -1):
                stamps: deque[float] = deque()
                packets = self._packets(capture, stamps, every)
                decoded = _ordered_map(
                    lambda packet: _decode_jpeg(packet, crop),
                    packets,
                    lambda index: f"frame {index * every} of {self._path}",
                )
                for frame in decoded:
                    yield stamps.popleft(), frame
                return
            for index in itertools.count():
                if not capture.grab():
                    return
                if index % every:
                    continue
                ok, frame = capture.retrieve()
                if not ok:
                    return
                stamp = capture.get(cv2.CAP_PROP_POS_MSEC) / 1e3
                yield stamp, cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY) if frame.ndim == 3 else frame
        finally:
            capture.release()

    @staticmethod
    def _packets(capture: cv2.VideoCapture, stamps: deque[float], every: int) -> Iterator[np.ndarray]:
        """Every ``every``-th raw packet in order, from the first; each one's presentation time (s)
        is appended to ``stamps``. Packets left out are read past, not copied."""
        for index in itertools.count():
            if index % every:
                if not capture.grab():
                    return
                continue
            ok, packet = capture.read()
            if not ok or packet is None:
                return
            stamps.append(capture.get(cv2.CAP_PROP_POS_MSEC) / 1e3)
            yield packet.reshape(-1).copy()
