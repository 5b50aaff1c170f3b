"""The files a run writes as it goes, the same live or simulated (see `rig.session`):

* `tracker.csv` every tracker sample as it reaches the host (`predictors.SAMPLE_COLUMNS`);
* `app_frames.csv` every application frame: when it started, what it cost and where that figure
  came from, when it finished, the photon time it predicted for, the newest sample behind it, and
  the position drawn;
* `display_frames.csv` every refresh that shows an image: which image, the row it lights, its
  photon time, the newest sample behind it, the sensor-to-photon delay, the x drawn, whether the
  refresh missed (the display repeats the previous refresh's image: the renderer had no new one
  ready), and what the work that made the image cost on the clock and where that figure came from;
* the camera's film, where the run has a camera (`FilmRecord`): `video.avi` and `camera_frames.csv`
  (or `video.mp4` or `video.mov`, with `frame_times.csv`, for a film in a container that stamps
  each frame with its own time, `rig.film_file`);
* `board/`, where the rig board records beside the run (`rig.board.instrument`, `rig.sim.board`).

`FilmRecord` is also what `rig record` films into. It appends each frame to the video
(Motion-JPEG by default) and a row to `camera_frames.csv` (`FRAME_COLUMNS`): the
frame's number in the video, when it was captured on the rig clock, the capture backend's own
timestamp where it has one, and whether the frame is a stand-in. A frame that comes more than
`DROP_FACTOR` typical intervals after the previous one (on the camera's schedule where it keeps
one, `CameraFrame.t_slot`) means the camera dropped frames; each missing one is filled with a copy
of the last frame (`filled` 1) so that frame i of an AVI stays at i intervals from the first,
which is all the time such a file holds. The typical interval is the median of the latest ones: a camera that
runs slower than it said is not dropping. Frames are encoded on a thread of the film's own, in the
order given: encoding one takes milliseconds, which a live run's render loop cannot spare.
A frame the video cannot take stops the film (RigError, from the next `write` or from `close`):
its row is not written, so `camera_frames.csv` lists exactly the frames the video holds.
"""

from __future__ import annotations

import contextlib
import queue
import threading
from collections import deque
from pathlib import Path
from typing import Any

import numpy as np

from analysis.video.native_path import native_path
from predictors import SAMPLE_COLUMNS
from rig.devices.protocols import CameraFrame
from rig.errors import RigError
from rig.film_file import StampedVideoRecord, check_film_rate, video_file_name
from rig.writers import CsvRecord, VideoRecord
from rig.session.run_files import APP_FRAMES_FILE, DISPLAY_FRAMES_FILE, FRAMES_FILE, TRACKER_FILE

APP_FRAME_COLUMNS = (
    "index", "t_start", "cost_s", "cost_source", "t_finish", "t_photon_target", "t_sensor_newest", "x", "y", "z",
)  # fmt: skip
DISPLAY_FRAME_COLUMNS = (
    "refresh", "t_vblank", "image", "row_fraction", "t_photon", "t_sensor_newest", "delay_ms", "x",
    "missed", "image_cost_s", "cost_source",
)  # fmt: skip
FRAME_COLUMNS = ("frame", "t_capture", "t_backend_ms", "filled")
DROP_FACTOR = 1.5
INTERVAL_WINDOW = 31
MAX_FILL = 120
"""Most stand-ins written for one gap: a longer silence is a stall, not a run of drops."""
QUEUED_FRAMES = 512
"""Frames waiting to be encoded at most; a caller writing more waits."""


Film = tuple[str, str]
"""A film's (container, codec), `rig.film_file`."""
MJPEG_AVI: Film = ("avi", "mjpeg")


class FilmRecord:
    """A camera's film in `out_dir` at `fps` (the rate the video states), in the `film`'s container
    and codec; see the module docstring."""

    def __init__(
        self, out_dir: Path, fps: float, width: int, height: int, *, film: Film = MJPEG_AVI, overwrite: bool = False
    ) -> None:
        self.video_path = Path(out_dir) / video_file_name(film[0])
        native_path(self.video_path)  # OpenCV would crash on a name that is not UTF-8: refused here
        check_film_rate(fps, film[0])  # before any file is made
        self.fps = fps
        self._table = CsvRecord(Path(out_dir) / FRAMES_FILE, FRAME_COLUMNS, overwrite=overwrite)
        try:
            self._video: VideoRecord | StampedVideoRecord = (
                VideoRecord(self.video_path, fps, width, height)
                if film == MJPEG_AVI
                else StampedVideoRecord(self.video_path, *film, fps, width, height)
            )
        except BaseException:
            self._table.close()
            raise
        self._intervals: deque[float] = deque(maxlen=INTERVAL_WINDOW)
        self._last: tuple[float, np.ndarray] | None = None
        self._first: float | None = None
        self.frames = 0
        self.dropped = 0
        self.stalls = 0
        self._queue: queue.Queue[CameraFrame | None] = queue.Queue(QUEUED_FRAMES)
        self._failure: Exception | None = None
        self._thread: threading.Thread | None = threading.Thread(target=self._encode, name=f"film {out_dir}", daemon=True)
        self._thread.start()

    @property
    def typical_interval_s(self) -> float:
        return float(np.median(self._intervals)) if len(self._intervals) >= 3 else 1.0 / self.fps

    def write(self, frame: CameraFrame) -> None:
        """Queue `frame` for the film (RigError once the film could not be written)."""
        if self._failure is not None:
            raise RigError(f"cannot write the film {self.video_path}: {self._failure}")
        self._queue.put(frame)

    def _encode(self) -> None:
        while (frame := self._queue.get()) is not None:
            if self._failure is None:
                try:
                    self._append_filled(frame)
                except Exception as error:  # noqa: BLE001 - raised to the writer by write() and close()
                    self._failure = error

    def _append_filled(self, frame: CameraFrame) -> None:
        """Append a frame, after the stand-ins for the frames dropped before it."""
        t_slot = frame.t_start if frame.t_slot is None else frame.t_slot
        if self._last is not None:
            t_previous, previous = self._last
            gap = t_slot - t_previous
            interval = self.typical_interval_s
            if gap > DROP_FACTOR * interval:
                missing = int(round(gap / interval)) - 1
                if missing > MAX_FILL:
                    self.stalls += 1
                else:
                    for i in range(1, missing + 1):
                        self._append(previous, t_previous + i * interval, None, True)
                    self.dropped += missing
            else:
                self._intervals.append(gap)
        self._append(frame.image, frame.t_start, frame.t_backend_ms, False)
        self._last = (t_slot, frame.image)
        if self._first is None:
            self._first = t_slot

    def _append(self, grey: np.ndarray, t: float, t_backend_ms: float | None, filled: bool) -> None:
        self._video.write(grey, t)
        self._table.write([self.frames, t, t_backend_ms, int(filled)])
        self.frames += 1

    def measured_fps(self) -> float | None:
        """The frame rate of the video as captured: frames (stand-ins included) over the time from the
        first to the last; None before two frames."""
        if self._first is None or self._last is None or self.frames < 2 or self._last[0] <= self._first:
            return None
        return (self.frames - 1) / (self._last[0] - self._first)

    def report(self) -> dict[str, Any]:
        """What the film holds (final once closed)."""
        return {"video": self.video_path.name, "fps": self.fps, "frames": self.frames, "dropped": self.dropped,
                "stalls": self.stalls, "measured_fps": self.measured_fps()}  # fmt: skip

    def close(self) -> None:
        """Encode what is queued and close the files; safe to call more than once."""
        thread, self._thread = self._thread, None
        if thread is None:
            return
        self._queue.put(None)
        thread.join()
        try:
            self._video.close()
        finally:
            self._table.close()
        if self._failure is not None:
            raise RigError(f"cannot write the film {self.video_path}: {self._failure}")


class RunRecord:
    """The open files of one run in `out_dir`; the film, in the `film`'s container and codec, once
    the session opens it for the run's camera (`open_film`, when the camera is connected and says
    what it delivers). Use as a context manager: every file is closed on any exit."""

    def __init__(self, out_dir: Path, overwrite: bool = False, film: Film = MJPEG_AVI) -> None:
        self.out_dir = Path(out_dir)
        self._overwrite = overwrite
        self._film_format = film
        self.film: FilmRecord | None = None
        self._stack = contextlib.ExitStack()
        with self._stack:
            self.tracker = self._stack.enter_context(CsvRecord(self.out_dir / TRACKER_FILE, SAMPLE_COLUMNS, overwrite=overwrite))
            self.app_frames = self._stack.enter_context(
                CsvRecord(self.out_dir / APP_FRAMES_FILE, APP_FRAME_COLUMNS, overwrite=overwrite)
            )
            self.display_frames = self._stack.enter_context(
                CsvRecord(self.out_dir / DISPLAY_FRAMES_FILE, DISPLAY_FRAME_COLUMNS, overwrite=overwrite)
            )
            self._stack = self._stack.pop_all()

    def open_film(self, fps: float, width: int, height: int) -> FilmRecord:
        """The camera's film, `fps` frames a second of `width` x `height`."""
        if self.film is not None:
            raise RigError(f"the run in {self.out_dir} already films")
        self.film = FilmRecord(self.out_dir, fps, width, height, film=self._film_format, overwrite=self._overwrite)
        self._stack.callback(self.film.close)
        return self.film

    @property
    def video_path(self) -> Path:
        return self.out_dir / video_file_name(self._film_format[0])

    def close(self) -> None:
        self._stack.close()

    def __enter__(self) -> RunRecord:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
