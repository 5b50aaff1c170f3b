"""A renderer's latency as the rig measures it: simulate the bench, film it, analyse the video.

Costs drive the virtual clock: measured on this machine by default (each application frame and
each composed image costs what its GL work took), or modelled where a run asks (a GPU-like server
cost, labelled "modelled"). The pendulum's period is stretched so the expected latency stays under
LATENCY_PERIOD_FRACTION of it (the analyser resolves latency only modulo a period); a latency that
would need a period over the run's limit is reported as beyond range. The spread reported is the
analyser's: the standard deviation of the latency measured swing by swing (as the seeds' Table 2
gives the spread over repeated measurements); the truth's per-display-frame delay spread is beside it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import analysis
from analysis import AnalysisError
from rig.service import SimulationConfig, simulate
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import PendulumConfig

LATENCY_PERIOD_FRACTION = 0.3
"""The pendulum period is at least the expected latency over this fraction (well below one half)."""
CAMERA_FRAMES_PER_PERIOD = 240.0
"""Camera frames per swing period (at most 240 fps, at least MIN_CAMERA_FPS)."""
MIN_CAMERA_FPS = 60.0
LATENCY_PERIODS = 3.0
"""Swing periods filmed at least (the analyser needs two)."""
BASE_LATENCY_S = 0.1
"""Transport, sampling, scan-out and hold, added to a renderer's own delays in the expected latency."""


@dataclass(frozen=True)
class LatencyRun:
    """One filmed run: a renderer spec on a load of `triangles` (shaped as `load` says,
    `rig.render.gl.LOAD_SHAPES`), a display of `size` at `refresh_hz`, a predictor and photon
    target, and its costs (ms, modelled; None: measured)."""

    renderer: str
    triangles: int
    size: tuple[int, int]
    predictor: str = "hold"
    predictor_params: tuple[tuple[str, Any], ...] = ()
    app_frame_ms: float | None = None
    server_ms: float | None = None
    photon_target: str = "photons"
    refresh_hz: float = 60.0
    camera: CameraConfig = CameraConfig()
    min_duration_s: float = 6.0
    max_period_s: float = 8.0
    load: str = "soup"

    @property
    def composes(self) -> bool:
        return not self.renderer.startswith("direct")

    @property
    def cost_source(self) -> str:
        """Where the cost that sets the latency comes from: a direct renderer's application frame,
        a compositing renderer's composed image."""
        return "measured" if (self.server_ms if self.composes else self.app_frame_ms) is None else "modelled"


def expected_latency_s(run: LatencyRun, app_frame_s: float, server_s: float) -> float:
    """A generous guess of the run's latency from its costs (s): a direct renderer's two frames; a
    compositing server's refreshes (a cost over one refresh makes it skip some)."""
    if not run.composes:
        return 2.0 * app_frame_s + BASE_LATENCY_S
    refresh_s = 1.0 / run.refresh_hz
    return (math.ceil(server_s / refresh_s) + 1) * refresh_s + BASE_LATENCY_S


def film_latency(run: LatencyRun, app_frame_s: float, server_s: float, out_dir: Path) -> dict[str, Any]:
    """Simulate `run` (with `app_frame_s` and `server_s` the costs expected, for the period), film it,
    analyse the video; its figures. Latencies are None when the expected one needs too long a period
    or the analyser fails, and the note says why."""
    expected_s = expected_latency_s(run, app_frame_s, server_s)
    period = max(PendulumConfig().period_s, expected_s / LATENCY_PERIOD_FRACTION)
    figures: dict[str, Any] = {"renderer": run.renderer, "triangles": run.triangles, "width": run.size[0], "height": run.size[1],
                               "predictor": run.predictor, "photon_target": run.photon_target, "cost_source": run.cost_source,
                               "latency_measured_ms": None, "latency_true_ms": None, "latency_sd_ms": None,
                               "frame_delay_sd_ms": None, "frame_ms_median": None, "missed_pct": None, "latency_period_s": None}  # fmt: skip
    if period > run.max_period_s:
        note = f"beyond range: about {expected_s:.1f} s expected, which needs a pendulum period over {run.max_period_s:g} s"
        return {**figures, "latency_note": note}
    width, height = run.size
    config = SimulationConfig(
        duration_s=max(run.min_duration_s, LATENCY_PERIODS * period),
        pendulum=PendulumConfig(period_s=period),
        display=DisplayConfig(refresh_hz=run.refresh_hz, width=width, height=height),
        camera=replace(run.camera, fps=min(240.0, max(MIN_CAMERA_FPS, CAMERA_FRAMES_PER_PERIOD / period))),
        renderer=run.renderer,
        predictor=run.predictor,
        predictor_params=dict(run.predictor_params),
        scene_triangles=run.triangles,
        scene_load=run.load,
        app_frame_ms=run.app_frame_ms,
        warp_ms=run.server_ms,
        photon_target=run.photon_target,
        # the first frame must be on show when filming starts; and the truth's latency search looks
        # up to about a period back, which the session's pendulum covers only within its warm-up
        warmup_s=max(app_frame_s + 0.5, period),
    )
    result = simulate(config, out_dir, overwrite=True)
    truth = result.truth
    frame_cost = truth.display_frame_cost if truth.display_frame_cost is not None else truth.app_frame_cost
    figures.update(
        latency_true_ms=truth.latency_ms,
        frame_delay_sd_ms=truth.display_frame_delay_ms.sd,
        frame_ms_median=frame_cost.get("median_ms", frame_cost.get("ms")),
        missed_pct=100.0 * truth.refreshes.missed / max(truth.refreshes.shown, 1),
        latency_period_s=period,
    )
    note = f"{result.cost_line()}; simulated at {width}x{height}, predictor {run.predictor}, target {run.photon_target}"
    try:
        # the ROIs of the simulated bench, as a lab marks them once for its camera
        measured = analysis.analyse(result.video_path, led_roi=truth.led_roi, sphere_roi=truth.sphere_roi)
    except AnalysisError as error:
        return {**figures, "latency_note": f"{note}; the analyser failed: {error}"}
    if measured.ambiguous:
        note += "; AMBIGUOUS (near half a period)"
    windowed = measured.windowed
    return {
        **figures,
        "latency_measured_ms": measured.latency_ms,
        "latency_sd_ms": windowed.sd_s * 1e3 if windowed is not None and windowed.count > 1 else None,
        "latency_note": note,
    }
