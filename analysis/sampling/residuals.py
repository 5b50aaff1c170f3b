"""The sphere's per-frame timing against the LED: where a display's refreshes show in a video.

The LED moves continuously; the sphere is a display's staircase seen through the camera's
exposure, so each frame shows it a little early or late (``analysis.sampling.model``). Against
the LED delayed by the measured latency, mapped onto the sphere's track by a cubic (a lens or a
display may bend one a little against the other) plus a slow drift, a frame's residual r is about
-v (b - mean b), v the sphere's speed and b that frame's timing bias: the pattern of the biases is
seen, their weighted mean is not (it is in the latency). Each frame's centroid row, and the spread
of the sphere's light over its rows, say when the display's scan-out and the camera's readout reach
it (``analysis.sampling.rows``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.longrun import long_run_variance
from analysis.signals import SwingSignals
from analysis.blobs import Track


@dataclass(frozen=True)
class TimingResiduals:
    """Per used frame: the sphere's time (s, from the first frame's), its residual r (px) and speed
    v (px/s) against the LED reference, the frame's index on the camera's frame grid (for spectra),
    and its centroid row (px; None without its track); row_sd is the standard deviation of its light
    over its rows (px; 0 where its moments were not measured), the median over frames."""

    t: np.ndarray
    r: np.ndarray
    v: np.ndarray
    index: np.ndarray
    frame_interval: float
    rows: np.ndarray | None = None
    row_sd: float = 0.0


def _catmull_rom(grid_t: np.ndarray, values: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(value, derivative, inside) of the Catmull-Rom spline through uniform samples at times t."""
    step = grid_t[1] - grid_t[0]
    x = (t - grid_t[0]) / step
    i = np.floor(x).astype(np.int64)
    inside = (i >= 1) & (i <= values.size - 3)
    i = np.clip(i, 1, values.size - 3)
    f = x - i
    p0, p1, p2, p3 = values[i - 1], values[i], values[i + 1], values[i + 2]
    a = -0.5 * p0 + 1.5 * p1 - 1.5 * p2 + 0.5 * p3
    b = p0 - 2.5 * p1 + 2.0 * p2 - 0.5 * p3
    c = -0.5 * p0 + 0.5 * p2
    value = ((a * f + b) * f + c) * f + p1
    slope = ((3 * a * f + 2 * b) * f + c) / step
    return value, slope, inside


def timing_residuals(
    signals: SwingSignals, latency_s: float, sphere_track: Track | None = None
) -> TimingResiduals | None:
    """The sphere's residuals and speeds at its own times against the LED delayed by ``latency_s``
    (see the module docstring), with its rows where ``sphere_track`` (its track over the signals'
    frames) is given; None when too few frames overlap."""
    grid, led, _ = signals.uniform()
    frame_interval = signals.frame_interval
    if grid.size < 8:
        return None
    level, slope, inside = _catmull_rom(grid, led, signals.sphere_t - latency_s)
    used = inside & signals.sphere_valid
    if np.count_nonzero(used) < 32:
        return None
    t, reference, rate = signals.sphere_t[used], level[used], slope[used]
    sphere = signals.sphere[used]
    scale = max(float(np.std(reference)), 1e-12)
    u = (reference - reference.mean()) / scale
    s = (t - t.mean()) / max(float(np.ptp(t)) / 2, 1e-12)
    basis = np.column_stack([np.ones_like(u), u, u**2, u**3, s, s**2])
    coefficients, *_ = np.linalg.lstsq(basis, sphere, rcond=None)
    residual = sphere - basis @ coefficients
    speed = (coefficients[1] + 2 * coefficients[2] * u + 3 * coefficients[3] * u**2) * rate / scale
    index = np.rint((signals.t[used] - signals.t[0]) / frame_interval).astype(np.int64)
    rows, row_sd = None, 0.0
    if sphere_track is not None:
        rows = sphere_track.y[used]
        if sphere_track.spread is not None:
            row_sd = float(np.sqrt(max(float(np.median(sphere_track.spread[sphere_track.valid, 1])), 0.0)))
    return TimingResiduals(t - signals.t[0], residual, speed, index, frame_interval, rows, row_sd)


def inflation(series: np.ndarray, bandwidth: int) -> float:
    """How much a sum of this series varies beyond as many independent terms: its long-run
    variance over its variance (at least 1)."""
    centred = series - series.mean()
    variance = float(centred @ centred)
    if variance <= 0:
        return 1.0
    return max(1.0, long_run_variance(centred, max(0, min(bandwidth, series.size - 1))) / variance)
