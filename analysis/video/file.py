"""A video file: Motion-JPEG read with OpenCV as raw packets decoded to grey, other codecs with PyAV.

A Motion-JPEG file's packets are read raw and decoded by ``analysis.video.decoding`` (grey straight
from libjpeg, only the crop's rectangle once it is set, a few frames ahead on a few threads); a
packet left out by ``every`` is read past, never decoded. Any other codec (H.264 and HEVC from
phones) is decoded whole by PyAV and cropped afterwards; each frame's stamp is its presentation
time in the container (its PTS on the stream's time base), so a film with variable frame timing
gives every frame's own time.
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
from analysis.video.frames import Crop, Frame, Repeats, checked_every, checked_fps, cut_frames, noted_repeats, same_image
from analysis.video.native_path import native_path

# Frame rates outside this range are not believed when a container states them.
PLAUSIBLE_FPS = (1.0, 10_000.0)

logger = logging.getLogger(__name__)


class VideoFile:
    """A video file read with OpenCV; its frames carry the container's presentation times."""

    def __init__(self, path: str | Path, fps: float | None = None) -> None:
        self._path = Path(path)
        if not self._path.is_file():
            raise AnalysisError(f"video file {self._path} does not exist; check the path")
        self._native_path = native_path(self._path)
        capture = cv2.VideoCapture(self._native_path)
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
        capture = cv2.VideoCapture(self._native_path)
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

    def frames(self, crop: Crop | None = None, every: int = 1, repeats: Repeats | None = None) -> Iterator[Frame]:
        every = checked_every(every)
        if self._raw_jpeg:
            return cut_frames(self._jpeg_frames(crop, every, repeats if every == 1 else None), crop)
        return cut_frames(noted_repeats(self._decoded_frames(every), repeats, every), crop)

    def _jpeg_frames(self, crop: Crop | None, every: int, repeats: Repeats | None) -> Generator[Frame, None, None]:
        capture = cv2.VideoCapture(self._native_path)
        try:
            if not capture.set(cv2.CAP_PROP_FORMAT, -1):
                raise AnalysisError(f"{self._path} no longer reads as Motion-JPEG packets; check that the file is not being written")
            stamps: deque[float] = deque()
            packets = self._packets(capture, stamps, every, repeats)
            decoded = ordered_map(
                lambda packet: decode_jpeg(packet, crop),
                packets,
                lambda index: f"frame {index * every} of {self._path}",
            )
            for frame in decoded:
                yield stamps.popleft(), frame
        finally:
            capture.release()

    @staticmethod
    def _packets(capture: cv2.VideoCapture, stamps: deque[float], every: int, repeats: Repeats | None) -> Iterator[np.ndarray]:
        """Every ``every``-th raw packet in order, from the first; each one's presentation time (s)
        is appended to ``stamps``, and a packet identical to the one before noted in ``repeats``.
        Packets left out are read past, not copied."""
        if repeats is not None:
            repeats.start()
        previous = None
        for index in itertools.count():
            if index % every:
                if not capture.grab():
                    return
                continue
            ok, packet = capture.read()
            if not ok or packet is None:
                return
            stamps.append(capture.get(cv2.CAP_PROP_POS_MSEC) / 1e3)
            packet = packet.reshape(-1).copy()
            if repeats is not None:
                repeats.note(index, same_image(packet, previous))
                previous = packet
            yield packet

    def _decoded_frames(self, every: int) -> Generator[Frame, None, None]:
        """Every ``every``-th frame, decoded whole to grey by PyAV, stamped with its presentation
        time (s; NaN for a frame without one)."""
        import av  # here: reading Motion-JPEG, the rig's own films, need not load FFmpeg

        try:
            container = av.open(self._native_path)
        except av.FFmpegError as error:
            raise AnalysisError(f"{self._path} cannot be decoded: {error}; re-record it or convert it to MP4") from None
        index = 0
        try:
            stream = container.streams.video[0]
            stream.thread_type = "AUTO"
            for index, frame in enumerate(container.decode(stream)):
                if index % every:
                    continue
                stamp = float(frame.pts * frame.time_base) if frame.pts is not None and frame.time_base is not None else math.nan
                yield stamp, frame.to_ndarray(format="gray")
        except av.FFmpegError as error:
            raise AnalysisError(f"{self._path} is corrupt after frame {index}: {error}; re-record it or leave it out") from None
        finally:
            container.close()
