"""The truth of a simulated run (`Truth`, written as truth.json): above all its true effective
latency, what an ideal video analyser would measure.

The display emits a step function: the sphere's x stays where a refresh drew it until the next
refresh reaches the sphere's row. The effective latency is the delay tau minimising

    J(tau) = integral over the filmed span of (x_shown(t) - x_led(t - tau))^2 dt,

found by a scan over one pendulum period around a guess (the mean sensor-to-photon delay), using
the LED signal tabulated once and interpolated, then refined with a bounded scalar minimiser that
evaluates the LED exactly.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from rig.devices.protocols import NO_IMAGE
from rig.errors import RigError
from rig.session import SessionLog
from rig.sim.config import SimulationConfig
from rig.sim.display import SimDisplay
from rig.sim.pendulum import Pendulum

GRID_STEP_S = 1e-4
SCAN_STEP_S = 1e-3
LATENCY_DEFINITION = (
    "delay tau minimising the mean squared difference between the sphere's x as the display emits it "
    "(hold, scan-out row) and the true LED x shifted by tau, over the filmed span"
)


def shown_signal(switch_times: np.ndarray, values: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Sample-and-hold: values[i] from switch_times[i] until the next switch; NaN before the first."""
    index = np.searchsorted(switch_times, t, side="right") - 1
    return np.where(index >= 0, values[np.maximum(index, 0)], np.nan)


def effective_latency(
    switch_times: np.ndarray,
    x_shown: np.ndarray,
    led_x: Callable[[np.ndarray], np.ndarray],
    span: tuple[float, float],
    period_s: float,
    guess_s: float = 0.0,
) -> float:
    """The delay tau (s) minimising the squared difference between x_shown(t) and led_x(t - tau)."""
    # Midpoints of a fine grid: no instant falls exactly on a switch, so the integral of the
    # step function is unbiased wherever the switches lie.
    t = np.arange(span[0], span[1], GRID_STEP_S) + GRID_STEP_S / 2
    shown = shown_signal(switch_times, x_shown, t)
    valid = np.isfinite(shown)
    t, shown = t[valid], shown[valid]

    def cost(tau: float) -> float:
        return float(np.mean((shown - led_x(t - tau)) ** 2))

    taus = np.arange(guess_s - period_s / 2, guess_s + period_s / 2, SCAN_STEP_S)
    table_t = np.arange(t[0] - taus[-1] - SCAN_STEP_S, t[-1] - taus[0] + SCAN_STEP_S, GRID_STEP_S)
    table_x = led_x(table_t)

    def coarse_cost(tau: float) -> float:
        return float(np.mean((shown - np.interp(t - tau, table_t, table_x)) ** 2))

    coarse = taus[int(np.argmin([coarse_cost(tau) for tau in taus]))]
    from scipy.optimize import minimize_scalar  # here: importing the rig's services need not load scipy.optimize

    fine = minimize_scalar(cost, bounds=(coarse - SCAN_STEP_S, coarse + SCAN_STEP_S), method="bounded", options={"xatol": 1e-7})
    return float(fine.x)


@dataclass(frozen=True)
class DelayStats:
    """Sensor-to-photon delay (ms) of every display frame switching within the filmed span."""

    mean: float
    sd: float
    values: list[float]


@dataclass(frozen=True)
class RefreshCount:
    """Refreshes within the filmed span that showed an image, and how many of them missed (repeated
    the previous refresh's image because the renderer had no new one ready)."""

    shown: int
    missed: int


@dataclass(frozen=True)
class FilmTruth:
    """How the camera filmed, beyond its rate: readout_ms, the rolling shutter's readout (0: a global
    shutter; row y of H exposed (y / H) x readout after row 0); led_row, sphere_row, the LED's and
    the sphere's mean rows over the film as fractions of the frame's height, so the sphere's timing
    in the video is shifted by (sphere_row - led_row) x readout against the LED's; container and
    codec, the film's file; frame_times, the file beside it listing each frame's exposure start and
    presentation time (None for an AVI, whose frame i is at i / fps)."""

    readout_ms: float
    led_row: float
    sphere_row: float
    container: str
    codec: str
    frame_times: str | None


@dataclass(frozen=True)
class Truth:
    """What a simulated run knows to be true, as written to truth.json.

    latency_ms: the true effective latency (see the module docstring); display_frame_delay_ms: the
    sensor-to-photon delay of each display frame (a repeated image's delay grows with each repeat);
    refreshes: how many refreshes showed an image and how many missed; app_frame_cost: what the
    clock charged per application frame; display_frame_cost: what it charged per composed image, for
    a renderer composing at refreshes (None for one that does not); each cost says whether it was
    "modelled" (its ms) or "measured" (median, 95th percentile and largest ms); camera_fps, frames:
    the film's rate and frame count (a decimated film's, where the camera's impairments decimate);
    led_roi, sphere_roi: where the LED and the sphere swing in the video (mirrored with the film);
    board: the rig board's clock offset, the pendulum's release and the blink (None without a
    board); config: the run's whole configuration; film: how the camera filmed (`FilmTruth`), left
    out of truth.json for a global-shutter, constant-rate MJPEG film on the default layout, as the
    film settings are left out of its config (`SimulationConfig.to_dict`).
    """

    latency_ms: float
    latency_definition: str
    display_frame_delay_ms: DelayStats
    refreshes: RefreshCount
    camera_fps: float
    frames: int
    period_s: float
    app_frame_cost: dict[str, Any]
    display_frame_cost: dict[str, Any] | None
    led_roi: list[int]
    sphere_roi: list[int]
    board: dict[str, Any] | None
    config: SimulationConfig
    film: FilmTruth | None = None

    def to_dict(self) -> dict[str, Any]:
        """The JSON-ready record (the config as plain values)."""
        record = asdict(self) | {"config": self.config.to_dict()}
        if self.film is None:
            del record["film"]
        return record

    def write(self, path: Path) -> None:
        try:
            Path(path).write_text(json.dumps(self.to_dict(), indent=2))
        except OSError as error:
            raise RigError(f"cannot write {path}: {error.strerror}") from None


def run_truth(
    config: SimulationConfig,
    pendulum: Pendulum,
    display: SimDisplay,
    log: SessionLog,
    camera_span: tuple[float, float],
    frames: int,
    rois: tuple[list[int], list[int]],
    costs: tuple[dict[str, Any], dict[str, Any] | None],
    board: dict[str, Any] | None,
    film: FilmTruth | None = None,
) -> Truth:
    """The truth of a finished run: what its display showed (`log`), against the pendulum's motion;
    `costs` are the application frames' and the composed display frames' (`Truth`)."""
    rows = [(k, log.shown[i]) for k, i in enumerate(log.content) if i != NO_IMAGE]
    content = np.array(log.content)
    repeated = np.r_[False, (content[1:] == content[:-1]) & (content[1:] != NO_IMAGE)]
    refreshes = np.array([k for k, _ in rows])
    switch_times = display.vblank_time(refreshes) + display.scanout_delay(np.array([s.row_fraction for _, s in rows]))
    x_shown = np.array([s.x_m for _, s in rows])
    newest = np.array([s.t_sensor_newest for _, s in rows])
    in_span = (switch_times >= camera_span[0]) & (switch_times <= camera_span[1])
    missed = int(repeated[refreshes[in_span]].sum())
    delays_ms = (switch_times - newest)[in_span] * 1e3
    latency_s = effective_latency(
        switch_times,
        x_shown,
        lambda t: pendulum.led_position(t)[:, 0],
        camera_span,
        pendulum.period_s,
        guess_s=float(delays_ms.mean()) / 1e3,
    )
    return Truth(
        latency_ms=latency_s * 1e3,
        latency_definition=LATENCY_DEFINITION,
        display_frame_delay_ms=DelayStats(
            mean=float(delays_ms.mean()),
            sd=float(delays_ms.std(ddof=1)) if len(delays_ms) > 1 else 0.0,
            values=[round(float(d), 6) for d in delays_ms],
        ),
        refreshes=RefreshCount(shown=int(in_span.sum()), missed=missed),
        camera_fps=config.camera.film_fps,
        frames=frames,
        period_s=pendulum.period_s,
        app_frame_cost=costs[0],
        display_frame_cost=costs[1],
        led_roi=rois[0],
        sphere_roi=rois[1],
        board=board,
        config=config,
        film=film,
    )
