"""Latency from the board alone: the photodiode on the display against the encoder at the pivot.

A photodiode fixed on the display sees the rendered sphere pass over it; the encoder sees the
pendulum. Both are timed by the board's one clock, so no clock sync enters. The latency D is the
time from the pendulum passing an angle to the display showing the sphere at that angle.

For each passage of the sphere the board reports the centroid of the photodiode signal, the moment
the sphere was centred on the photodiode (rig/board/protocol.h, rig_msg_passage_t). With
the photodiode at encoder angle p (in counts, unknown) and angle(t) the encoder's count
interpolated between edges (an edge from c - step to c is the boundary c - step / 2):

    angle(centroid_j - D) = p        for every passage j

D and p follow by least squares on these residuals weighted by 1 / speed (so they are seconds):
for a given D, p is a weighted mean; D minimises the residuals over a grid, then a bounded search;
its uncertainty comes from the Jacobian of the time residuals. Passages in both directions of
swing are needed: one direction alone cannot tell a later display from a photodiode further along.
(Threshold crossings alone cannot either: where the sphere trips a threshold depends on its size
and brightness exactly as on D. That is why the board reports centroids.)

A latency D and one of D + T/2 (T the pendulum period) fit equally well with p mirrored, so D is
searched below `max_latency_s`, by default 0.45 T; give it if the latency could be longer.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from analysis.board.recording import ENCODER, PASSAGES, TICK_HZ, load_table
from analysis.errors import AnalysisError

VELOCITY_WINDOW_S = 0.005
# Passages lasting more than this many times the median happen near a turning point, where an
# encoder count is a long time and the speed poorly known: they are left out.
SLOW_PASSAGE_FACTOR = 2.0
GRID_STEP_S = 2e-4
MIN_PASSAGES = 4
DEFAULT_MAX_LATENCY_PERIODS = 0.45


@dataclass(frozen=True)
class BoardLatency:
    latency_s: float
    uncertainty_s: float
    photodiode_counts: float
    passages_used: int
    passages_seen: int
    rms_residual_s: float
    period_s: float
    max_latency_s: float

    def as_dict(self) -> dict[str, float | int]:
        return asdict(self)


@dataclass(frozen=True)
class EncoderTrajectory:
    """The pendulum's angle in encoder counts against board time, linear between edges."""

    times: NDArray[np.float64]
    angles: NDArray[np.float64]

    def angle(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.interp(t, self.times, self.angles)

    def velocity(self, t: NDArray[np.float64]) -> NDArray[np.float64]:
        h = VELOCITY_WINDOW_S
        return (self.angle(t + h) - self.angle(t - h)) / (2 * h)


def encoder_trajectory(edge_times: ArrayLike, counts: ArrayLike, steps: ArrayLike) -> EncoderTrajectory:
    """From encoder.csv's columns: an edge from count - step to count is the angle count - step / 2."""
    times = np.asarray(edge_times, dtype=np.float64)
    angles = np.asarray(counts, dtype=np.float64) - 0.5 * np.asarray(steps, dtype=np.float64)
    order = np.argsort(times, kind="stable")
    times, angles = times[order], angles[order]
    keep = np.append(np.diff(times) > 0, True)
    if keep.sum() < 10:
        raise AnalysisError("the recording has fewer than 10 encoder edges: was the pendulum swinging?")
    return EncoderTrajectory(times[keep], angles[keep])


def _period(trajectory: EncoderTrajectory) -> float:
    """Median time between upward crossings of the mean angle."""
    centred = trajectory.angles - np.mean(trajectory.angles)
    upward = np.flatnonzero((centred[:-1] < 0) & (centred[1:] >= 0))
    if upward.size < 2:
        raise AnalysisError("the encoder recording spans less than one pendulum period: record longer")
    return float(np.median(np.diff(trajectory.times[upward])))


class _Fit:
    """The least-squares problem of the module docstring."""

    def __init__(self, trajectory: EncoderTrajectory, centroids: NDArray[np.float64]) -> None:
        self.trajectory = trajectory
        self.centroids = centroids
        self.top_speed = float(np.max(np.abs(trajectory.velocity(trajectory.times))))

    def residuals(self, delay: float) -> tuple[NDArray[np.float64], NDArray[np.float64], float] | None:
        """Time residuals, their Jacobian (columns D, p) and p; None when the passages at this
        delay do not go both ways or fall where the pendulum stands still."""
        shown = self.centroids - delay
        speed = self.trajectory.velocity(shown)
        direction = np.sign(speed)
        if np.any(np.abs(speed) < 1e-3 * self.top_speed) or np.all(direction == direction[0]):
            return None
        weight = 1.0 / np.abs(speed)
        angles = self.trajectory.angle(shown)
        position = float(np.sum(angles * weight**2) / np.sum(weight**2))
        residuals = (angles - position) * weight
        jacobian = np.column_stack([-direction, -weight])
        return residuals, jacobian, position

    def cost(self, delay: float) -> float:
        fitted = self.residuals(delay)
        return np.inf if fitted is None else float(np.mean(fitted[0] ** 2))


def estimate_board_latency(
    edge_times: ArrayLike,
    counts: ArrayLike,
    steps: ArrayLike,
    centroid_times: ArrayLike,
    durations: ArrayLike,
    *,
    max_latency_s: float | None = None,
) -> BoardLatency:
    """Latency from encoder edges (board s; count after the edge; its step, +1 or -1) and the
    photodiode passages (board s of each centroid; how long each lasted); see the module docstring."""
    trajectory = encoder_trajectory(edge_times, counts, steps)
    period = _period(trajectory)
    limit = DEFAULT_MAX_LATENCY_PERIODS * period if max_latency_s is None else max_latency_s
    if not 0 < limit < 0.5 * period:
        raise AnalysisError(
            f"the largest latency searched must lie between 0 and half the pendulum period ({500 * period:.1f} ms), "
            f"got {1e3 * limit:.1f} ms: beyond it a latency D and D + T/2 look the same"
        )
    centroids = np.asarray(centroid_times, dtype=np.float64)
    lasted = np.asarray(durations, dtype=np.float64)
    if centroids.shape != lasted.shape or centroids.size < MIN_PASSAGES:
        raise AnalysisError(f"need at least {MIN_PASSAGES} passages of the sphere over the photodiode, got {centroids.size}")
    usable = lasted <= SLOW_PASSAGE_FACTOR * np.median(lasted)
    usable &= centroids - limit - VELOCITY_WINDOW_S >= trajectory.times[0]
    usable &= centroids + VELOCITY_WINDOW_S <= trajectory.times[-1]
    if usable.sum() < MIN_PASSAGES:
        raise AnalysisError(
            f"only {usable.sum()} passages of the sphere fall within the encoder recording at a good speed; "
            f"need {MIN_PASSAGES}: record longer, or place the photodiode where the pendulum moves fast"
        )
    fit = _Fit(trajectory, centroids[usable])
    grid = np.arange(0.0, limit + GRID_STEP_S, GRID_STEP_S)
    costs = np.array([fit.cost(delay) for delay in grid])
    if not np.isfinite(costs).any():
        raise AnalysisError("the passages over the photodiode do not fit the pendulum: they need both directions of swing")
    best = int(np.argmin(costs))
    from scipy.optimize import minimize_scalar  # here: the camera path imports this module for its encoder model alone

    refined = minimize_scalar(
        fit.cost,
        bounds=(max(0.0, grid[best] - GRID_STEP_S), min(limit, grid[best] + GRID_STEP_S)),
        method="bounded",
        options={"xatol": 1e-8},
    )
    delay = float(refined.x) if refined.fun <= costs[best] else float(grid[best])
    residuals, jacobian, position = fit.residuals(delay)
    dof = max(residuals.size - jacobian.shape[1], 1)
    covariance = float(np.sum(residuals**2)) / dof * np.linalg.pinv(jacobian.T @ jacobian)
    return BoardLatency(
        latency_s=delay,
        uncertainty_s=float(np.sqrt(covariance[0, 0])),
        photodiode_counts=position,
        passages_used=int(residuals.size),
        passages_seen=int(centroids.size),
        rms_residual_s=float(np.sqrt(np.mean(residuals**2))),
        period_s=period,
        max_latency_s=limit,
    )


def estimate_from_recording(out_dir: Path, *, max_latency_s: float | None = None) -> BoardLatency:
    """The latency of a `rig board record` folder (its encoder.csv and passages.csv)."""
    encoder = load_table(out_dir, ENCODER.name)
    passages = load_table(out_dir, PASSAGES.name)
    tick_s = 1.0 / TICK_HZ
    return estimate_board_latency(
        encoder["board_time_s"],
        encoder["count"],
        encoder["step"],
        passages["board_time_s"],
        (passages["end_tick"] - passages["start_tick"]) * tick_s,
        max_latency_s=max_latency_s,
    )


def plot_board_latency(out_dir: Path, latency: BoardLatency, path: Path) -> Path:
    """A PNG for people: the encoder's angle over the recording, with every passage of the sphere
    moved back by the latency (each should sit on the swing, at the photodiode's angle), and each
    passage's residual."""
    from matplotlib.figure import Figure  # imported here so that importing analysis.board stays light

    encoder = load_table(out_dir, ENCODER.name)
    passages = load_table(out_dir, PASSAGES.name)
    trajectory = encoder_trajectory(encoder["board_time_s"], encoder["count"], encoder["step"])
    shown = passages["board_time_s"] - latency.latency_s
    speed = trajectory.velocity(shown)
    residual = (trajectory.angle(shown) - latency.photodiode_counts) / np.where(speed == 0, np.inf, np.abs(speed))
    figure = Figure(figsize=(10, 6))
    swing, residuals = figure.subplots(2, 1, sharex=True)
    swing.plot(trajectory.times, trajectory.angles, "-", linewidth=0.8, label="encoder angle (counts)")
    swing.plot(shown, np.full(shown.shape, latency.photodiode_counts), "o", label="passages, moved back by the latency")
    swing.set_ylabel("encoder counts")
    swing.legend(loc="upper right")
    swing.set_title(f"board latency {latency.latency_s * 1e3:.3f} ms +- {latency.uncertainty_s * 1e3:.3f} ms")
    residuals.plot(shown, residual * 1e6, "o")
    residuals.set_xlabel("board time (s)")
    residuals.set_ylabel("residual (us)")
    try:
        figure.savefig(path, dpi=100)
    except OSError as error:
        raise AnalysisError(f"cannot write the plot {path}: {error}") from None
    return Path(path)
