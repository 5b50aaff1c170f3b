"""Recording a camera (`rig record`), its live preview, and the guided check of the first seconds.

`record_camera` films for a duration into a folder: the film a run's camera makes
(`rig.session.run_record.FilmRecord`: `video.avi`, or `video.mp4` for a camera faster than an AVI
holds (`rig.film_file.film_holding`), and `camera_frames.csv`) and `camera.json` (the camera's
report and the film's); Ctrl-C or an unplugged camera stops it with every frame kept. With a
preview, a window shows the newest frame with both regions of interest drawn (given, or found by
the analyser's calibration on the first second and a half of swing).

`check_first_seconds` is the guided mode's check before a long run: it records a few seconds and
asks whether both blobs are found and whether the exposure leaves them unsaturated.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Callable

import cv2
import numpy as np

from analysis.calibration import calibrate
from analysis.errors import AnalysisError
from analysis.video.sources import open_frames
from rig.clock import MonotonicClock
from rig.devices.camera.opencv_camera import opencv_camera
from rig.devices.protocols import CameraFrame
from rig.devices.window.gl_window import GlWindow, WindowSettings
from rig.errors import RigError
from rig.film_file import film_holding
from rig.fresh_outputs import removed_unless_recorded
from rig.session.run_record import FilmRecord

PREVIEW_EVERY_S = 1.0 / 30.0
ROI_FRAMES = 90
SETTINGS_FILE = "camera.json"
SATURATED = 255
SATURATED_SHARE = 0.002
"""More of the image than this at full scale is an exposure too long (the LED's core aside)."""
LED_COLOUR, SPHERE_COLOUR = (255, 200, 0), (0, 200, 255)


class Preview:
    """A window showing camera frames with the LED's and the sphere's ROIs drawn."""

    def __init__(self, rois: tuple[list[int], list[int]] | None) -> None:
        self.rois = rois
        self._window = GlWindow(WindowSettings(title="latency rig: camera preview"))
        self._held: list[np.ndarray] = []

    def show(self, grey: np.ndarray) -> None:
        if self.rois is None:
            self._held.append(grey)
            if len(self._held) >= ROI_FRAMES:
                self.rois = find_rois(self._held)
                self._held = []
        image = cv2.cvtColor(grey, cv2.COLOR_GRAY2RGB)
        for roi, colour in zip(self.rois or (), (LED_COLOUR, SPHERE_COLOUR)):
            x, y, w, h = roi
            cv2.rectangle(image, (x, y), (x + w - 1, y + h - 1), colour, 2)
        with self._window.current():
            self._window.draw(image)
            self._window.swap()
        if self._window.closing():
            raise KeyboardInterrupt

    def close(self) -> None:
        self._window.close()


def find_rois(frames: list[np.ndarray], led_side: str | None = None) -> tuple[list[int], list[int]] | None:
    """(LED, sphere) ROIs the analyser finds in these frames, None where it finds none."""
    try:
        found = calibrate(frames, None, led_side, [])
    except AnalysisError:
        return None
    return found.led.roi.as_list(), found.sphere.roi.as_list()


def record_camera(
    spec: str,
    duration_s: float,
    out_dir: Path,
    *,
    preview: bool = False,
    rois: tuple[list[int], list[int]] | None = None,
    accept_refused: bool = False,
    overwrite: bool = False,
    progress: Callable[[float, float], None] = lambda done, total: None,
) -> dict[str, Any]:
    """Film `spec` for `duration_s` into `out_dir` (see the module docstring); camera.json's content."""
    camera = opencv_camera(spec, accept_refused=accept_refused)
    window = Preview(rois) if preview else None
    clock = MonotonicClock()
    film: FilmRecord | None = None
    report: dict[str, Any] = {"partial": True}
    with removed_unless_recorded(out_dir):
        try:
            camera.connect(clock)
            container_and_codec = film_holding(camera.fps)
            out_dir.mkdir(parents=True, exist_ok=True)
            film = FilmRecord(out_dir, camera.fps, camera.width, camera.height, film=container_and_codec, overwrite=overwrite)
            end = clock.now() + duration_s
            while (now := clock.now()) < end and not camera.finished and camera.fault() is None:
                _film(camera.poll(), film, window)
                progress(min(now, end), end)
                clock.wait_until(min(end, clock.now() + PREVIEW_EVERY_S))
            report["partial"] = False
        finally:
            camera.close()
            if window is not None:
                window.close()
            if film is not None:
                _film(camera.poll(), film, None)
                film.close()
                report = {**camera.report(), **film.report(), **report}
                (out_dir / SETTINGS_FILE).write_text(json.dumps(report, indent=1) + "\n", encoding="utf-8")
        if (fault := camera.fault()) is not None:
            kept = f"everything captured before is in {out_dir}" if film is not None and film.frames else "nothing was captured"
            raise RigError(f"{fault.reason} at {fault.since:.3f} s; {kept}")
    return report


def _film(frames: list[CameraFrame], film: FilmRecord, window: Preview | None) -> None:
    for frame in frames:
        film.write(frame)
    if window is not None and frames:
        window.show(frames[-1].image)


def check_first_seconds(video: Path, led_side: str | None = None) -> list[str]:
    """What is wrong with the first seconds of a bench video (empty: ready for a long run)."""
    source = open_frames(video)
    frames = [image for _, image in source.frames()]
    if len(frames) < 10:
        return [f"the camera delivered {len(frames)} frames; check that it films"]
    problems = []
    saturated = float(np.mean([np.mean(frame >= SATURATED) for frame in frames]))
    if saturated > SATURATED_SHARE:
        problems.append(f"{saturated:.1%} of the image is saturated: shorten the exposure (or dim the monitor) until "
                        "only the LED's core is")  # fmt: skip
    rois = find_rois(frames[-ROI_FRAMES:], led_side)
    if rois is None:
        problems.append("the analyser does not find two moving bright blobs (the LED and the sphere): check that the "
                        "pendulum swings, the renderer draws, and both are in view")  # fmt: skip
    return problems

