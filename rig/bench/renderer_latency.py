"""A renderer's latency as the rig measures it: simulate the bench, film it, analyse the video.

Costs drive the virtual clock: measured on this machine by default (each application frame and
each composed image costs what its GL work took), or modelled where a run asks (a GPU-like server
cost, labelled "modelled"). The pendulum's period is stretched so the expected latency stays under
LATENCY_PERIOD_FRACTION of it (the analyser resolves latency only modulo a period); a latency that
would need a period over the run's limit is reported as beyond range. The spread reported is the
analyser's: the standard deviation of the latency measured swing by swing (as the seeds' Table 2
gives the spread over repeated measurements); the truth's per-display-frame delay spread is beside it.

A film is a sweep's point (`rig.service.sweep`), analysed within the regions the simulation put the
LED and the sphere in: `film_latencies` films many as one sweep, written out as FILMS_SPEC so that
`rig sweep` films them again, `film_latency` one at a time.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any

from predictors import make as make_predictor
from rig.bench.contract import Context
from rig.bench.renderer_specs import LatencyRun
from rig.service.analyse import AnalysisRequest
from rig.service.batch import USER_ERRORS
from rig.service.sweep import (
    SIMULATED_ROIS, PointRun, Sweep, SweepPoint, run_sweep, settings_of, simulate_and_analyse, unsimulated_row, write_sweep,
)
from rig.sim.config import SimulationConfig
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
FILMS_SPEC = "films.toml"
"""The sweep of a bench's films, written beside their runs (`film_latencies`)."""


def composes(renderer: str) -> bool:
    """Whether a renderer spec composes images at refreshes (a warp) rather than drawing each frame (direct)."""
    return not renderer.startswith("direct")


Film = tuple[dict[str, Any], LatencyRun, float, float]
"""A film to make: its labels, its run, and the application frame's and the server's expected costs (s)."""


def expected_latency_s(run: LatencyRun, app_frame_s: float, server_s: float) -> float:
    """A generous guess of the run's latency from its costs (s): a direct renderer's two frames; a
    compositing server's refreshes (a cost over one refresh makes it skip some)."""
    if not composes(run.config.renderer):
        return 2.0 * app_frame_s + BASE_LATENCY_S
    refresh_s = 1.0 / run.config.display.refresh_hz
    return (math.ceil(server_s / refresh_s) + 1) * refresh_s + BASE_LATENCY_S


def _period_s(run: LatencyRun, app_frame_s: float, server_s: float) -> tuple[float, float]:
    """The expected latency (s) and the pendulum period that keeps it within LATENCY_PERIOD_FRACTION."""
    expected_s = expected_latency_s(run, app_frame_s, server_s)
    return expected_s, max(PendulumConfig().period_s, expected_s / LATENCY_PERIOD_FRACTION)


def film_config(run: LatencyRun, app_frame_s: float, server_s: float) -> SimulationConfig:
    """The simulation that films `run`, with `app_frame_s` and `server_s` the costs expected (s):
    they set the pendulum's period, the film's length and frame rate, and the warm-up."""
    _, period = _period_s(run, app_frame_s, server_s)
    return replace(
        run.config,
        duration_s=max(run.min_duration_s, LATENCY_PERIODS * period),
        pendulum=PendulumConfig(period_s=period),
        camera=replace(run.config.camera, fps=min(240.0, max(MIN_CAMERA_FPS, CAMERA_FRAMES_PER_PERIOD / period))),
        # the first frame must be on show when filming starts; and the truth's latency search looks
        # up to about a period back, which the session's pendulum covers only within its warm-up
        warmup_s=max(app_frame_s + 0.5, period),
    )


def _no_figures(config: SimulationConfig) -> dict[str, Any]:
    """A run's figures with nothing filmed: what it is, every latency None, nothing failed."""
    cost = config.warp_ms if composes(config.renderer) else config.app_frame_ms
    return {"renderer": config.renderer, "triangles": config.scene_triangles, "width": config.display.width,
            "height": config.display.height, "predictor": config.predictor, "photon_target": config.photon_target,
            "cost_source": "measured" if cost is None else "modelled",
            "latency_measured_ms": None, "latency_true_ms": None, "latency_sd_ms": None,
            "frame_delay_sd_ms": None, "frame_ms_median": None, "missed_pct": None, "latency_period_s": None,
            "failed": None}  # fmt: skip


def beyond_range_figures(run: LatencyRun, app_frame_s: float, server_s: float) -> dict[str, Any] | None:
    """The figures of a run that cannot be filmed with these costs expected (its period would be
    over the run's limit), the note saying why; None when it can be."""
    expected_s, period = _period_s(run, app_frame_s, server_s)
    if period <= run.max_period_s:
        return None
    note = f"beyond range: about {expected_s:.1f} s expected, which needs a pendulum period over {run.max_period_s:g} s"
    return {**_no_figures(run.config), "latency_note": note}


def film_figures(filmed: PointRun) -> dict[str, Any]:
    """A filmed run's figures: its costs, missed refreshes and frame delay spread from the truth,
    the latency measured and its spread swing by swing from the analysis, and a note of the run."""
    config, truth, row = filmed.simulation.truth.config, filmed.simulation.truth, filmed.row
    frame_cost = truth.display_frame_cost if truth.display_frame_cost is not None else truth.app_frame_cost
    figures = _no_figures(config) | {
        "latency_true_ms": truth.latency_ms,
        "frame_delay_sd_ms": truth.display_frame_delay_ms.sd,
        "frame_ms_median": frame_cost.get("median_ms", frame_cost.get("ms")),
        "missed_pct": 100.0 * truth.refreshes.missed / max(truth.refreshes.shown, 1),
        "latency_period_s": config.pendulum.period_s,
    }
    note = (f"{filmed.simulation.cost_line()}; simulated at {config.display.width}x{config.display.height}, "
            f"predictor {config.predictor}, target {config.photon_target}")  # fmt: skip
    if filmed.result is None:
        return {**figures, "latency_note": f"{note}; the analyser failed: {row['error']}", "failed": f"the analyser failed: {row['error']}"}
    if filmed.result.ambiguous:
        note += "; AMBIGUOUS (near half a period)"
    windowed = filmed.result.windowed
    return {
        **figures,
        "latency_measured_ms": filmed.result.latency_ms,
        "latency_sd_ms": windowed.sd_s * 1e3 if windowed is not None and windowed.count > 1 else None,
        "latency_note": note,
    }


def failed_figures(config: SimulationConfig, reason: str) -> dict[str, Any]:
    """The figures of a run that was not filmed (its simulation refused, its costs not timed): failed with `reason`."""
    return {**_no_figures(config), "latency_note": reason, "failed": reason}


def check_predictors(*names: str | None) -> None:
    """Make each predictor named (None: none) once: one that cannot be made is refused
    (PredictorError) before a bench times or films anything, not a failed film per load."""
    for name in names:
        if name is not None:
            make_predictor(name)


def film_row(point: SweepPoint) -> dict[str, Any]:
    """A sweep job: the point's summary row (simulated, then analysed within the simulation's
    regions, as a lab marks them once for its camera), with its film's figures under "film"."""
    try:
        filmed = simulate_and_analyse(point)
    except USER_ERRORS as error:
        return unsimulated_row(point, error) | {"film": failed_figures(point.config, f"not simulated: {error}")}
    return filmed.row | {"film": film_figures(filmed)}


def film_latency(run: LatencyRun, app_frame_s: float, server_s: float, out_dir: Path) -> dict[str, Any]:
    """Simulate `run` (with `app_frame_s` and `server_s` the costs expected, for the period), film it,
    analyse the video; its figures. Latencies are None when the expected one needs too long a period
    or the run cannot be simulated or analysed, and the note says why (`failed` too where it could
    not be simulated or analysed)."""
    unfilmed = beyond_range_figures(run, app_frame_s, server_s)
    if unfilmed is not None:
        return unfilmed
    point = SweepPoint(0, film_config(run, app_frame_s, server_s), {}, out_dir, AnalysisRequest(out_dir / "video.avi"), simulated_rois=True)
    return film_row(point)["film"]


def film_latencies(films: list[Film], comment: str, context: Context) -> list[dict[str, Any]]:
    """Each film's figures, in order. A film beyond range is not filmed (its note says why); the
    others are a sweep of explicit points with their labels, analysed within the simulation's
    regions, written to the context's folder as FILMS_SPEC under `comment` and run by
    `rig.service.sweep` with `film_row` into that folder (pointNNN, summary.csv and .json; on the
    context's executor, with its progress bar), so that `rig sweep` on that file films exactly
    them again."""
    progress = context.progress("filming the latency films")
    figures = [beyond_range_figures(run, app_s, server_s) for _, run, app_s, server_s in films]
    points = [
        {"labels": labels, **settings_of(film_config(run, app_s, server_s))}
        for (labels, run, app_s, server_s), unfilmed in zip(films, figures)
        if unfilmed is None
    ]
    if not points:
        return figures
    sweep = Sweep({}, {}, {SIMULATED_ROIS: True}, points)
    folder = context.folder
    write_sweep(sweep, folder / FILMS_SPEC, comment)
    rows, _ = run_sweep(sweep, folder, context.workers, context.scheduler, progress, overwrite=True, job=film_row)
    filmed = iter(row["film"] for row in rows)
    return [next(filmed) if unfilmed is None else unfilmed for unfilmed in figures]
