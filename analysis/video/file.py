"""A video file read with OpenCV: Motion-JPEG as raw packets decoded to grey, other codecs the ordinary way.

A Motion-JPEG file's packets are read raw and decoded by ``analysis.video.decoding`` (grey straight
from libjpeg, only the crop's rectangle once it is set, a few frames ahead on a few threads); a
packet left out by ``every`` is read past, never decoded. Any other codec is read the ordinary way
and cropped afterwards.
"""

from __future__ import annotations

import itertools
import logging
import math
from collections import deque
from collections.abc import Generator, Iterator
from pathlib import Path

import cv2
import numpy as np

from analysis.errors import AnalysisError
from analysis.video.decoding import REGION_DECODER_MISSING, decode_jpeg, decodes_regions, ordered_map
from analysis.video.frames import Crop, Frame, checked_every, checked_fps, cut_frames

# Frame rates outside this range are not believed when a container states them.
PLAUSIBLE_FPS = (1.0, 10_000.0)

logger = logging.getLogger(__name__)


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
        if self._raw_jpeg and not decodes_regions():
            logger.warning(REGION_DECODER_MISSING)

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
        """True for Motion-JPEG: a packet left out is never decoded, and a crop is decoded alone.

        Without the region decoder a crop is decoded whole and cut; the file is still read as a
        sample, then again, so that it gives the same tracks whether the decoder is built or not.
        """
        return self._raw_jpeg

    def frames(self, crop: Crop | None = None, every: int = 1) -> Iterator[Frame]:
        return cut_frames(self._grey_frames(crop, checked_every(every)), crop)

    def _grey_frames(self, crop: Crop | None, every: int) -> Generator[Frame, None, None]:
        capture = cv2.VideoCapture(str(self._path))
        try:
            if self._raw_jpeg and capture.set(cv2.CAP_PROP_FORMAT, -1):
                stamps: deque[float] = deque()
                packets = self._packets(capture, stamps, every)
                decoded = ordered_map(
                    lambda packet: decode_jpeg(packet, crop),
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
