"""Measure a camera's shutter from a film of a flashing light (`analysis.shutter`), as a lab asks:
a light flashing at a known frequency, or a display flashing full-field at a known rate."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

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


def _ms(seconds: float) -> float:
    """Seconds as milliseconds to the tenth of a microsecond, as a bench profile holds them."""
    return round(seconds * 1e3, 4)


def bench_changes(result: ShutterResult, film: Path, when: str) -> dict[str, dict[str, Any]]:
    """What `rig calibrate-camera --bench` writes into the bench profile (`rig.service.bench_profile`):
    the camera's frame rate (the film's), exposure and readout (0 for a global shutter) with their
    95 % intervals and the direction the rows are read in, each from this calibration (`when`, a
    date, and the film's name)."""
    source = f"rig calibrate-camera {when} from {Path(film).name}"
    return {
        "camera": {
            "fps": round(result.fps, 4),
            "fps_source": f"{source} (its frame times)",
            "exposure_ms": _ms(result.exposure_s),
            "exposure_ci95_ms": tuple(_ms(v) for v in result.exposure_ci95_s),
            "exposure_source": source,
            "readout_ms": _ms(result.readout_s),
            "readout_ci95_ms": tuple(_ms(v) for v in result.readout_ci95_s),
            "readout_direction": result.readout_direction,
            "readout_source": source + (" (a global shutter)" if result.global_shutter else ""),
        }
    }
