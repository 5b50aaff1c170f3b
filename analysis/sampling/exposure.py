"""The camera's exposure, from the LED's motion blur against its speed, or as the user gives it.

A point of light moving at speed v during an exposure E is smeared along its path by v E: the
blob's intensity-weighted variance along the motion exceeds its variance across it by (v E)^2 / 12,
whatever the spot's shape, as long as the sensor answers linearly. Over the frames of a swing v
runs from zero to its largest, so the slope of that excess against v^2 is E^2 / 12 (an intercept
takes the spot's own asymmetry). A saturated core flattens more along the smear than across it,
which makes the excess too large, by about 40 % for a smear shorter than the spot and less the
longer the smear (a few per cent at ten spot sizes): for a saturated LED the exposure is taken as
up to ``saturation_excess`` times smaller than the estimate. The camera cannot expose for longer
than its frame interval.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from analysis.blobs import Track

# A pixel at this level or above is saturated (8-bit video).
SATURATED_LEVEL = 254.5
# The LED counts as saturated when its brightest pixel is in more than this fraction of its frames.
SATURATED_FRAMES = 0.2
# The estimate's systematic range: the exposure lies within [estimate / low, estimate * high]...
LINEAR_RANGE = (1.15, 1.15)
# ...and for a saturated LED low grows by the saturation's excess (see saturation_excess).
SATURATED_HIGH = 1.1
SATURATION_EXCESS = (1.05, 0.45, 4.0)
# Frames used: the blob measured and moving at least this fraction of the LED's top speed.
MIN_SPEED_FRACTION = 0.2
# Residuals beyond this many robust deviations (a frame half hidden, a blink) are left out.
OUTLIER_SIGMAS = 4.0
MAD_TO_SIGMA = 1.4826


@dataclass(frozen=True)
class Exposure:
    """The camera's exposure: the range it lies in (s) and where that came from ("given", "LED
    blur", or "unknown" when the blur could not be measured); estimate_s is the blur's own figure."""

    low_s: float
    high_s: float
    source: str
    estimate_s: float | None = None

    def to_dict(self) -> dict[str, object]:
        return {
            "low_ms": self.low_s * 1e3,
            "high_ms": self.high_s * 1e3,
            "source": self.source,
            "estimate_ms": None if self.estimate_s is None else self.estimate_s * 1e3,
        }


def given_exposure(exposure_s: float, frame_interval: float) -> Exposure:
    """The exposure the user gives; it cannot exceed the frame interval."""
    exposure = min(exposure_s, frame_interval)
    return Exposure(exposure, exposure, "given", exposure)


def elongation_along(spread: np.ndarray, axis: tuple[np.ndarray, np.ndarray] | np.ndarray) -> np.ndarray:
    """Per frame, a blob's variance along ``axis`` (a unit vector, or one per frame) less across
    it (px^2), from its moments xx, yy, xy."""
    sxx, syy, sxy = spread.T
    ux, uy = axis
    return (ux * ux - uy * uy) * (sxx - syy) + 4 * ux * uy * sxy


def _velocities(track: Track) -> tuple[np.ndarray, np.ndarray]:
    """Per frame (vx, vy) in px/s by central differences between valid neighbours (NaN elsewhere)."""
    t, x, y = track.t, track.x, track.y
    vx, vy = np.full(t.size, np.nan), np.full(t.size, np.nan)
    inner = slice(1, -1)
    dt = t[2:] - t[:-2]
    vx[inner] = (x[2:] - x[:-2]) / dt
    vy[inner] = (y[2:] - y[:-2]) / dt
    return vx, vy


def exposure_from_blur(led: Track, frame_interval: float) -> Exposure:
    """The exposure from the LED's blur against its speed (see the module docstring)."""
    unknown = Exposure(0.0, frame_interval, "unknown")
    if led.spread is None or led.level is None:
        return unknown
    vx, vy = _velocities(led)
    speed2 = vx**2 + vy**2
    sxx, syy, sxy = led.spread.T
    with np.errstate(invalid="ignore", divide="ignore"):
        ux, uy = vx / np.sqrt(speed2), vy / np.sqrt(speed2)
        across = uy * uy * sxx - 2 * ux * uy * sxy + ux * ux * syy
        excess = elongation_along(led.spread, (ux, uy))
    usable = np.isfinite(excess) & np.isfinite(speed2)
    if np.count_nonzero(usable) < 20:
        return unknown
    usable &= speed2 >= (MIN_SPEED_FRACTION**2) * np.nanpercentile(speed2[usable], 99)
    slope, error = _slope(speed2[usable], excess[usable])
    if slope is None or slope - 2 * error <= 0:
        return unknown
    estimate = math.sqrt(12 * slope)
    saturated = np.mean(led.level[led.valid] >= SATURATED_LEVEL) > SATURATED_FRAMES
    spot = math.sqrt(max(float(np.median(across[usable])), 1e-12))
    smear = estimate * math.sqrt(float(np.percentile(speed2[usable], 90)))
    below, above = (saturation_excess(smear / spot), SATURATED_HIGH) if saturated else LINEAR_RANGE
    spread = math.sqrt(12 * (slope + 2 * error)) / estimate
    low = estimate / below / spread
    high = min(estimate * above * spread, frame_interval)
    return Exposure(min(low, high), high, "LED blur", min(estimate, frame_interval))


def saturation_excess(smear_spots: float) -> float:
    """By how much a saturated spot's blur overstates the exposure, at most, for a smear of
    ``smear_spots`` spot sizes (standard deviations): measured on simulated Gaussian LEDs
    saturated 1 to 12 times over, with a margin."""
    margin, excess, scale = SATURATION_EXCESS
    return margin * (1 + excess / (1 + (smear_spots / scale) ** 2))


def _slope(speed2: np.ndarray, excess: np.ndarray) -> tuple[float | None, float]:
    """(slope, its standard error) of excess = c + slope speed2, fitted again without outliers."""
    keep = np.ones(speed2.size, dtype=bool)
    for _ in range(3):
        if np.count_nonzero(keep) < 10:
            return None, math.inf
        basis = np.column_stack([np.ones(np.count_nonzero(keep)), speed2[keep]])
        coefficients, *_ = np.linalg.lstsq(basis, excess[keep], rcond=None)
        residual = excess - (coefficients[0] + coefficients[1] * speed2)
        variance = float(np.linalg.inv(basis.T @ basis)[1, 1]) * float(np.mean(residual[keep] ** 2))
        scale = MAD_TO_SIGMA * float(np.median(np.abs(residual[keep])))
        keep = np.abs(residual) <= OUTLIER_SIGMAS * max(scale, 1e-12)
    return float(coefficients[1]), math.sqrt(variance)
