"""What a camera's shutter was measured to be, and what the film showed (``ShutterResult``)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any


@dataclass(frozen=True)
class ShutterResult:
    """A camera's readout and exposure, each with its 95 % interval, in SI units.

    readout_s is the time the camera takes to start exposing its last row after its first (the
    whole frame's height; 0 for a global shutter, whose interval then reads (0, bound)); exposure_s
    how long each row is exposed; fps the film's frame rate. line_time_s is readout_s over the
    frame's rows, readout_direction "top-down" or "bottom-up" as the rows are read in the film
    (None for a global shutter). The rest is what the film showed: the flash frequency the frames'
    timing saw, the light's duty cycle, how many flash periods the bands span across the rows used
    (the light's own scan-out removed for a display) and how many rows each ramp between bands is
    long (None without bands), the rows, frames and pixels used, the frames' times against the
    bands (timing_rms_s), how far the rows depart from the model (misfit, a share of their swing),
    and warnings.
    """

    readout_s: float
    readout_ci95_s: tuple[float, float]
    exposure_s: float
    exposure_ci95_s: tuple[float, float]
    fps: float
    line_time_s: float
    global_shutter: bool
    readout_direction: str | None
    source: str
    flash_hz: float
    flash_hz_seen: float
    duty: float
    band_periods: float
    ramp_rows: float | None
    rows: tuple[int, int]
    row_count: int
    frame_height: int
    frames: int
    lit_pixels: int
    saturated_pixels: int
    timing_source: str
    timing_rms_s: float
    misfit: float
    warnings: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types: intervals as lists, an unknown number as None."""
        record = asdict(self)
        for key, value in record.items():
            if isinstance(value, tuple):
                record[key] = list(value)
            elif isinstance(value, float) and not math.isfinite(value):
                record[key] = None
        return record
