"""The files a camera's film may be written to: an MJPEG AVI (`rig.writers.VideoRecord`, frame i at
i / fps), or H.264 or HEVC in an MP4 or a MOV, as phones record, written through PyAV
(`StampedVideoRecord`), where every frame carries its own presentation time.

A stamped film's times are on a 1/90000 s time base (that of MPEG streams): each frame's
presentation time is its exposure's start rounded to it, counted from the first frame's, and
`frame_times.csv` beside the film lists both for every frame. The grey image is written as
full-range luma (chroma neutral), so decoding the film to grey gives back the pixels the codec kept.
A packet the file cannot take (a full disk) raises RigError, and closing counts the film's frames
back: RigError unless it holds every frame written. Such a film is written up to `STAMPED_MAX_FPS`
(10000 fps, each rate to it filmed and read back frame by frame in the tests); `film_holding` picks
the film a camera's rate needs.
"""

from __future__ import annotations

import os
from fractions import Fraction
from pathlib import Path

import numpy as np

from rig.errors import ConfigError, RigError
from rig.film_formats import STAMPED_CONTAINERS, check_film_format
from rig.writers import MJPEG_AVI_MAX_FPS, CsvRecord, check_avi_rate

TIME_BASE = Fraction(1, 90_000)
FRAME_TIMES_FILE = "frame_times.csv"
FRAME_TIME_COLUMNS = ("frame", "t_start", "pts", "t_presented")
# What PyAV encodes each codec with, and its settings: quality close to a phone's, at a speed a
# simulation can afford.
_ENCODERS = {
    "h264": ("libx264", {"preset": "veryfast", "crf": "16"}),
    "hevc": ("libx265", {"preset": "fast", "crf": "18", "x265-params": "log-level=error"}),
}
_FULL_RANGE = 2  # AVCOL_RANGE_JPEG: luma 0..255
_NEUTRAL_CHROMA = 128


STAMPED_MAX_FPS = 10_000.0
"""The fastest film written in an MP4 or a MOV: the fastest camera the rig simulates, each frame nine
or more ticks of the time base after the one before."""


def check_film_rate(fps: float, container: str, advice: str = "") -> None:
    """RigError unless a film in `container` holds `fps` frames a second (`check_avi_rate` for an
    AVI); `advice` says what else the caller may film in."""
    if container not in STAMPED_CONTAINERS:
        check_avi_rate(fps, advice)
    elif not fps <= STAMPED_MAX_FPS:
        raise RigError(
            f"a film in an MP4 or a MOV is written at most {STAMPED_MAX_FPS:g} frames a second, not {fps:g}: "
            f"film at {STAMPED_MAX_FPS:g} fps or fewer"
        )


def film_holding(fps: float) -> tuple[str, str]:
    """The (container, codec) a camera filming `fps` frames a second is written in: an MJPEG AVI, which
    every OpenCV build reads, where it holds the rate, else H.264 in an MP4 (each frame stamped with
    its time); RigError above what either holds."""
    film = ("avi", "mjpeg") if fps <= MJPEG_AVI_MAX_FPS else ("mp4", "h264")
    check_film_rate(fps, film[0])
    return film


def video_file_name(container: str) -> str:
    """The name of a run's film in its folder."""
    return f"video.{container}"


def stamped_frame_count(path: Path) -> int:
    """The frames an MP4's or a MOV's video stream holds, as its index lists them (0 for a file
    that does not open)."""
    import av

    try:
        with av.open(str(path)) as film:
            return film.streams.video[0].frames if film.streams.video else 0
    except (av.error.FFmpegError, OSError):
        return 0


class StampedVideoRecord:
    """Writes 8-bit grey frames, each with its presentation time, as H.264 or HEVC in an MP4 or a
    MOV, and lists every frame's time in `frame_times.csv` beside it. Release it on any exit (use it
    as a context manager): frames the encoder still holds are written then."""

    def __init__(self, path: str | os.PathLike[str], container: str, codec: str, fps: float, width: int, height: int) -> None:
        check_film_format(container, codec, stamped=False)
        if container not in STAMPED_CONTAINERS:
            raise ConfigError(f"an {container} film is written by rig.writers.VideoRecord, not with timestamps")
        import av  # here: only a run writing such a film loads FFmpeg

        self.path = Path(path)
        encoder, options = _ENCODERS[codec]
        try:
            self._file = av.open(str(self.path), "w", format=container)
        except OSError as error:
            raise RigError(f"cannot write video {self.path}: {error.strerror}") from None
        self._stream = self._file.add_stream(encoder, rate=Fraction(fps).limit_denominator(1001), options=options)
        self._stream.width, self._stream.height = width, height
        self._stream.pix_fmt = "yuv420p"
        self._stream.time_base = TIME_BASE
        self._stream.codec_context.time_base = TIME_BASE
        self._stream.codec_context.color_range = _FULL_RANGE
        self._frame_type = av.VideoFrame
        self._size = (width, height)
        self._times = CsvRecord(self.path.parent / FRAME_TIMES_FILE, FRAME_TIME_COLUMNS, overwrite=True, flush_each_row=False)
        self._first: float | None = None
        self._last_pts = -1
        self.frames = 0
        self.muxed = 0
        """Frames in the file so far: the encoder holds a few frames back before it writes them."""

    def write(self, grey: np.ndarray, t_start: float | None = None) -> None:
        """Append a frame whose exposure started at `t_start` (s on the rig clock)."""
        if t_start is None:
            raise ValueError("a stamped film needs each frame's start time")
        if self._first is None:
            self._first = t_start
        pts = round((t_start - self._first) / TIME_BASE)
        if pts <= self._last_pts:
            raise RigError(f"frame {self.frames} of {self.path} does not follow the one before on the film's time base")
        width, height = self._size
        planes = np.full((height * 3 // 2, width), _NEUTRAL_CHROMA, dtype=np.uint8)
        planes[:height] = grey
        frame = self._frame_type.from_ndarray(planes, format="yuv420p")
        frame.color_range = _FULL_RANGE
        frame.pts, frame.time_base = pts, TIME_BASE
        self._mux(frame)
        self._times.write([self.frames, float(t_start), pts, float(pts * TIME_BASE)])
        self._last_pts = pts
        self.frames += 1

    def _mux(self, frame: object) -> None:
        """Encode `frame` (None: what the encoder still holds) and write its packets to the file."""
        import av

        try:
            for packet in self._stream.encode(frame):
                self._file.mux(packet)
                self.muxed += 1
        except (av.error.FFmpegError, OSError) as error:
            raise RigError(
                f"{self.path} could not take a frame ({error}; is the disk full?): it holds {self.muxed} of the "
                f"{self.frames} frames {FRAME_TIMES_FILE} lists"
            ) from None

    def close(self) -> None:
        """Write what the encoder holds, close the files and count the film's frames back (RigError
        unless it holds every frame written); safe to call more than once."""
        if self._file is None:
            return
        try:
            self._mux(None)
        finally:
            self._file.close()
            self._file = None
            self._times.close()
        held = stamped_frame_count(self.path)
        if held != self.frames:
            raise RigError(f"{self.path} holds {held} of the {self.frames} frames written to it; check the disk and film again")

    def __enter__(self) -> StampedVideoRecord:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
