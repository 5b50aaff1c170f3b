"""Measure a camera's shutter from a film of a flashing light (`analysis.shutter`), as a lab asks:
a light flashing at a known frequency, or a display flashing full-field at a known rate."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from analysis.shutter import DisplayScan, ShutterResult, measure_shutter
from rig.errors import ConfigError

SOURCES = ("light", "display")


@dataclass(frozen=True)
class CalibrationRequest:
    """What to measure the shutter from: `film` shows `source` flashing at `flash_hz`, on for `duty`
    of each period (None: not known); a display is described by `display_hz`, the way its scan-out
    moves in the film (`scanout`) and its scan-out's share of a refresh (`scanout_share`, None: not
    known). `roi` (x, y, w, h) limits where the light is looked for, `fps` overrides the film's
    frame rate, and `max_exposure_s` is the longest the camera's exposure can be (None: a frame
    interval)."""

    film: Path
    flash_hz: float
    source: str = "light"
    duty: float | None = 0.5
    display_hz: float | None = None
    scanout: str = "top-down"
    scanout_share: float | None = None
    roi: tuple[int, int, int, int] | None = None
    fps: float | None = None
    max_exposure_s: float | None = None


def calibrate_camera(request: CalibrationRequest, progress: Callable[[int, int], object] | None = None) -> ShutterResult:
    """The camera's readout and exposure from the request's film; `progress(done, total)` as it is read."""
    if request.source not in SOURCES:
        raise ConfigError(f"the source is one of {', '.join(SOURCES)}, not {request.source!r}")
    display = None
    if request.source == "display":
        if request.display_hz is None:
            raise ConfigError("a flashing display's scan-out must be accounted for: give its refresh rate (--display-hz)")
        display = DisplayScan(request.display_hz, request.scanout, request.scanout_share)
    elif request.display_hz is not None:
        raise ConfigError("--display-hz describes a flashing display: give --source display with it, or leave it out")
    return measure_shutter(
        request.film,
        request.flash_hz,
        fps=request.fps,
        roi=request.roi,
        duty=request.duty,
        display=display,
        max_exposure_s=request.max_exposure_s,
        progress=progress,
    )
