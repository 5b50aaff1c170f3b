"""Camera frames to disk as they come: the video, a row per frame with its times, and dropped frames.

`FrameWriter` appends each frame to `video.avi` (Motion-JPEG, what the analyser reads) and a row to
`camera_frames.csv` (`FRAME_COLUMNS`): the frame's number in the video, when it was captured on the
rig clock, the backend's own timestamp where it has one, and whether the frame is a stand-in. A
frame that comes more than `DROP_FACTOR` typical intervals after the previous one means the camera
dropped frames; each missing one is filled with a copy of the last frame (`filled` 1) so that frame
i of the video stays at i intervals from the first, which the analyser assumes. The typical
interval is the median of the latest ones: a camera that runs slower than it said is not dropping.
"""

from __future__ import annotations

from collections import deque
from pathlib import Path

import numpy as np

from rig.records import CsvRecord, VideoRecord

VIDEO_FILE = "video.avi"
FRAMES_FILE = "camera_frames.csv"
FRAME_COLUMNS = ("frame", "t_capture", "t_backend_ms", "filled")
DROP_FACTOR = 1.5
INTERVAL_WINDOW = 31
# Most stand-ins written for one gap: a longer silence is a stall, not a run of drops.
MAX_FILL = 120


class FrameWriter:
    """The video and frame table of one capture in `out_dir`, at `fps` (the rate the video states)."""

    def __init__(self, out_dir: Path, fps: float, width: int, height: int, *, overwrite: bool = False) -> None:
        self.video_path = Path(out_dir) / VIDEO_FILE
        self._table = CsvRecord(Path(out_dir) / FRAMES_FILE, FRAME_COLUMNS, overwrite=overwrite)
        try:
            self._video = VideoRecord(self.video_path, fps, width, height)
        except BaseException:
            self._table.close()
            raise
        self.nominal_interval_s = 1.0 / fps
        self._intervals: deque[float] = deque(maxlen=INTERVAL_WINDOW)
        self._last: tuple[float, np.ndarray] | None = None
        self._first: float | None = None
        self.frames = 0
        self.dropped = 0
        self.stalls = 0

    @property
    def typical_interval_s(self) -> float:
        return float(np.median(self._intervals)) if len(self._intervals) >= 3 else self.nominal_interval_s

    def write(self, grey: np.ndarray, t_capture: float, t_backend_ms: float | None, t_slot: float | None = None) -> int:
        """Append a frame captured at `t_capture`; how many dropped frames were filled before it.
        `t_slot` is where the frame belongs on the camera's schedule where the camera knows it
        (drops are then found from the schedule, not from the capture times' jitter)."""
        filled = 0
        t_slot = t_capture if t_slot is None else t_slot
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
                    filled = missing
                    self.dropped += missing
            else:
                self._intervals.append(gap)
        self._append(grey, t_capture, t_backend_ms, False)
        self._last = (t_slot, grey)
        if self._first is None:
            self._first = t_slot
        return filled

    def _append(self, grey: np.ndarray, t: float, t_backend_ms: float | None, filled: bool) -> None:
        self._video.write(grey)
        self._table.write([self.frames, t, t_backend_ms, int(filled)])
        self.frames += 1

    def measured_fps(self) -> float | None:
        """The frame rate of the video as captured: frames (stand-ins included) over the time from the
        first to the last; None before two frames."""
        if self._first is None or self._last is None or self.frames < 2 or self._last[0] <= self._first:
            return None
        return (self.frames - 1) / (self._last[0] - self._first)

    def close(self) -> None:
        self._video.close()
        self._table.close()
