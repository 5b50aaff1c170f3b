"""From blob tracks to the two swing signals the estimators compare.

Each track is reduced to one signal, its displacement along its main axis of motion (pixels), at
its own times: a rolling shutter exposes each blob when the readout reaches its rows
(``analysis.readout``), so the LED's and the sphere's samples of one frame may be dated apart.
Invalid frames stay NaN here; each estimator decides how to treat them: the fits give them no
weight, the FFT and cross-correlation interpolate over them on a uniform time grid.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from analysis.errors import AnalysisError
from analysis.blobs import Track

# A track whose displacement along its axis has a smaller standard deviation does not move.
MIN_MOTION_PX = 0.5
# An axis whose x component is smaller than this is taken as vertical (see main_axis).
VERTICAL_X = 0.05


@dataclass(frozen=True)
class SwingSignals:
    """Both signals per frame (px), NaN where a blob was not found or not used: the LED's at times
    t (s), the sphere's at sphere_times (None: at t, both blobs exposed at once)."""

    t: np.ndarray
    led: np.ndarray
    sphere: np.ndarray
    sphere_times: np.ndarray | None = None

    @property
    def sphere_t(self) -> np.ndarray:
        """The sphere's sample times (s)."""
        return self.t if self.sphere_times is None else self.sphere_times

    @property
    def led_valid(self) -> np.ndarray:
        return np.isfinite(self.led)

    @property
    def sphere_valid(self) -> np.ndarray:
        return np.isfinite(self.sphere)

    @property
    def frame_interval(self) -> float:
        """The median time between frames (s)."""
        return float(np.median(np.diff(self.t)))

    def uniform(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t, led, sphere) on a uniform grid at the median frame interval from the LED's first time,
        each signal interpolated from its own times (gaps too): exact where they are the grid's."""
        step = self.frame_interval
        count = int(np.floor((self.t[-1] - self.t[0]) / step + 1e-9)) + 1
        grid = self.t[0] + step * np.arange(count)
        return grid, _interpolated(grid, self.t, self.led), _interpolated(grid, self.sphere_t, self.sphere)


def _interpolated(grid: np.ndarray, t: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``values`` (NaN where missing) at times ``t``, increasing, interpolated at ``grid`` by the cubic
    through the two valid samples either side (linearly with fewer than four valid samples, and
    held beyond the ends). A cubic, not a line, because a signal dated off the grid (a rolling
    shutter's rows) is moved by a fraction of a frame everywhere, and a line between samples
    delays a sine by up to about (omega dt)^3 / 60 radians: 0.07 ms at 30 fps on a 0.6 s swing."""
    valid = np.isfinite(values)
    times, known = t[valid], values[valid]
    if times.size < 4:
        return np.interp(grid, times, known)
    index = np.clip(np.searchsorted(times, grid) - 2, 0, times.size - 4)
    nodes = index[:, None] + np.arange(4)[None, :]
    x, y = times[nodes], known[nodes]
    result = np.zeros(grid.size)
    for j in range(4):
        basis = np.ones(grid.size)
        for k in range(4):
            if k != j:
                basis *= (grid - x[:, k]) / (x[:, j] - x[:, k])
        result += basis * y[:, j]
    inside = (grid >= times[0]) & (grid <= times[-1])
    return np.where(inside, result, np.interp(grid, times, known))


def main_axis(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Unit vector along which the points (x, y) spread most (their first principal axis).

    Its sign follows a fixed rule so that two tracks of the same swing share it: the x component
    is positive, or for a vertical axis (|x component| < VERTICAL_X) the y component is. The LED
    and the sphere must therefore move the same way in the image (a mirrored display would read as
    half a period of extra latency).
    """
    points = np.column_stack([x - x.mean(), y - y.mean()])
    _, vectors = np.linalg.eigh(points.T @ points)
    axis = vectors[:, -1]
    flip = axis[1] < 0 if abs(axis[0]) < VERTICAL_X else axis[0] < 0
    return -axis if flip else axis


def axis_signal(track: Track, name: str) -> np.ndarray:
    """A track's displacement along its main axis, mean removed, NaN where the track is invalid."""
    valid = track.valid
    if np.count_nonzero(valid) < 2:
        raise AnalysisError(f"the {name} was found in fewer than two frames; check its ROI")
    x, y = track.x[valid], track.y[valid]
    axis = main_axis(x, y)
    along = (x - x.mean()) * axis[0] + (y - y.mean()) * axis[1]
    if along.std() < MIN_MOTION_PX:
        raise AnalysisError(
            f"the {name} does not move (it swings less than {MIN_MOTION_PX} px); "
            f"check that the pendulum swings and that the {name} ROI holds the moving {name}"
        )
    signal = np.full(track.t.size, np.nan)
    signal[valid] = along - along.mean()
    return signal


def swing_signals(led: Track, sphere: Track) -> SwingSignals:
    """The LED's and the sphere's axis signals, each at its track's times (one frame each)."""
    return SwingSignals(led.t, axis_signal(led, "LED"), axis_signal(sphere, "sphere"), sphere.t)


@dataclass(frozen=True)
class BinnedSignals:
    """Signals averaged in time bins: per bin and signal the mean time and value of its valid
    frames, and how many there were (times and values NaN where there were none).

    Averaging k neighbouring frames is the same linear filter for both signals, so it changes
    neither their relative phase nor the model's form (a pendulum's swing is smooth on the scale
    of a few frames); it lets one fit run over a fixed number of samples per period.
    """

    led_t: np.ndarray
    led: np.ndarray
    led_count: np.ndarray
    sphere_t: np.ndarray
    sphere: np.ndarray
    sphere_count: np.ndarray
    frames_per_bin: int


def _bin_means(t: np.ndarray, values: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    count = t.size // size * size
    times = t[:count].reshape(-1, size)
    block = values[:count].reshape(-1, size)
    valid = np.isfinite(block)
    number = valid.sum(axis=1)
    safe = np.maximum(number, 1)
    mean_t = np.where(number > 0, (times * valid).sum(axis=1) / safe, np.nan)
    mean_value = np.where(number > 0, np.where(valid, block, 0.0).sum(axis=1) / safe, np.nan)
    return mean_t, mean_value, number


def binned(signals: SwingSignals, frames_per_bin: int) -> BinnedSignals:
    """Average every ``frames_per_bin`` consecutive frames, each signal over its valid frames."""
    if signals.t.size < frames_per_bin:
        raise AnalysisError("too few frames to analyse; record at least a few pendulum periods")
    led = _bin_means(signals.t, signals.led, frames_per_bin)
    sphere = _bin_means(signals.sphere_t, signals.sphere, frames_per_bin)
    return BinnedSignals(*led, *sphere, frames_per_bin)
