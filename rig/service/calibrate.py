"""Measure a camera's shutter from a film of a flashing light (`analysis.shutter`), as a lab asks:
a light flashing at a known frequency, or a display flashing full-field at a known rate."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

from analysis.shutter import ShutterOptions, ShutterResult, measure_shutter


@dataclass(frozen=True)
class CalibrationRequest:
    """What to measure the shutter from: `film` shows a light (or a display) flashing at `flash_hz`,
    read as `options` say (`analysis.shutter.ShutterOptions`)."""

    film: Path
    flash_hz: float
    options: ShutterOptions = field(default_factory=ShutterOptions)


def calibrate_camera(request: CalibrationRequest, progress: Callable[[int, int], object] | None = None) -> ShutterResult:
    """The camera's readout and exposure from the request's film; `progress(done, total)` as it is read."""
    return measure_shutter(request.film, request.flash_hz, request.options, progress)
