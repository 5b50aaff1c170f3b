"""The files a run writes as it goes, the same live or simulated (see `rig.session`):

* `tracker.csv` every tracker sample as it reaches the host (`predictors.SAMPLE_COLUMNS`);
* `app_frames.csv` every application frame: when it started, what it cost and where that figure
  came from, when it finished, the photon time it predicted for, the newest sample behind it, and
  the position drawn;
* `display_frames.csv` every refresh that shows an image: which image, the row it lights, its
  photon time, the newest sample behind it, the sensor-to-photon delay, the x drawn, whether the
  refresh missed (the display repeats the previous refresh's image: the renderer had no new one
  ready), and what the work that made the image cost on the clock and where that figure came from;
* `video.avi` the camera's frames, where the run has a camera it records itself (or `video.mp4` or
  `video.mov`, with `frame_times.csv`, for a film in a container that stamps each frame,
  `rig.film_file`).
"""

from __future__ import annotations

import contextlib
from pathlib import Path

from predictors import SAMPLE_COLUMNS
from rig.film_file import StampedVideoRecord, video_file_name
from rig.records import CsvRecord, VideoRecord

TRACKER_FILE = "tracker.csv"
APP_FRAMES_FILE = "app_frames.csv"
DISPLAY_FRAMES_FILE = "display_frames.csv"
VIDEO_FILE = "video.avi"
RUN_FILES = (VIDEO_FILE, TRACKER_FILE, APP_FRAMES_FILE, DISPLAY_FRAMES_FILE)
APP_FRAME_COLUMNS = (
    "index", "t_start", "cost_s", "cost_source", "t_finish", "t_photon_target", "t_sensor_newest", "x", "y", "z",
)  # fmt: skip
DISPLAY_FRAME_COLUMNS = (
    "refresh", "t_vblank", "image", "row_fraction", "t_photon", "t_sensor_newest", "delay_ms", "x",
    "missed", "image_cost_s", "cost_source",
)  # fmt: skip


class RunRecord:
    """The open files of one run in `out_dir`; `video_size` (fps, width, height) for a camera the run
    records, None for none, and `film` its (container, codec) (`rig.film_file`). Use as a context
    manager: every file is closed on any exit."""

    def __init__(
        self,
        out_dir: Path,
        video_size: tuple[float, int, int] | None,
        overwrite: bool = False,
        film: tuple[str, str] = ("avi", "mjpeg"),
    ) -> None:
        self.out_dir = Path(out_dir)
        self._video_file = video_file_name(film[0])
        self._stack = contextlib.ExitStack()
        with self._stack:
            self.tracker = self._stack.enter_context(CsvRecord(self.out_dir / TRACKER_FILE, SAMPLE_COLUMNS, overwrite=overwrite))
            self.app_frames = self._stack.enter_context(
                CsvRecord(self.out_dir / APP_FRAMES_FILE, APP_FRAME_COLUMNS, overwrite=overwrite)
            )
            self.display_frames = self._stack.enter_context(
                CsvRecord(self.out_dir / DISPLAY_FRAMES_FILE, DISPLAY_FRAME_COLUMNS, overwrite=overwrite)
            )
            self.video = self._stack.enter_context(self._video_record(video_size, film)) if video_size else None
            self._stack = self._stack.pop_all()

    def _video_record(self, size: tuple[float, int, int], film: tuple[str, str]) -> VideoRecord | StampedVideoRecord:
        if film == ("avi", "mjpeg"):
            return VideoRecord(self.video_path, *size)
        return StampedVideoRecord(self.video_path, *film, *size)

    @property
    def video_path(self) -> Path:
        return self.out_dir / self._video_file

    def close(self) -> None:
        self._stack.close()

    def __enter__(self) -> RunRecord:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
