"""`rig bench renderers` (its command line declared in `rig.bench.renderers_settings`): what it measures.

For each display resolution and load of N triangles (a load that cannot be drawn is rows failed with
the reason, and the others still run; a latency film that fails is its rows' reason too):

* direct: the real frame time on this machine (render and readback, wall clock);
* warp (the grid's warp spec, `warp` by default): the client's frame time, the server's time per
  display frame (wall clock until the GPU has finished, without readback, and the GL timer query
  beside it), timed in rounds that interleave all N so that a drift in machine load touches every
  N alike; and the image error of warped frames against a direct render at the same pose. For a
  client:display rate ratio of 1:r, a client frame drawn at the pendulum's pose at t0 is warped to
  its poses at t0 + k refreshes, k = 1..r (the seeds' synchronised client-server mode), at several
  phases of the swing; the figures are the means over all of them: the percentage of pixels whose
  CIE Lab distance exceeds 10 after a 3-pixel Gaussian blur, SSIM, DSSIM, PSNR, and the percentage
  of level-0 hole pixels left for the fill.

Both also report this process's CPU time per frame (all threads, readback included): on a machine
shared with other work, wall times carry their load, CPU times hardly.

Latency, at the first resolution: the rig is simulated, filmed and analysed
(`rig.bench.renderer_latency`), its costs measured on the virtual clock as they happen (a frame
that takes longer than a refresh misses refreshes), or the server's modelled where the grid says
(`server_ms`, labelled). Once the timings have given each film its expected costs, the films are
a sweep (`rig.service.sweep`) of explicit points, written beside the runs as films.toml, so that
`rig sweep films.toml --out DIR` films exactly those again.

The grid is `BenchGrid`, each setting declared once with its default; a spec (`--spec`, and
`specs/renderers-quick.toml` for `--quick`) sets any of them, read by `read_grid`, the grid's
options over it. The subject's modes
(`rig.bench.seed_table`, `rig.bench.warp_variants`, `rig.bench.photon_residual`) build on these
parts and share its options and outputs.
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace
from typing import Any

import numpy as np

from predictors import Pose
from rig.bench import renderer_plots
from rig.bench.contract import Bench, Context, Log, given
from rig.bench.renderer_latency import check_predictors, film_latencies
from rig.bench.renderer_rows import every_row_failed, table, untimed_rows
from rig.bench.renderer_setup import IDENTITY, WarpMeasurement, machine_name, open_warp, pose_of, scene_setup, warp_renderer
from rig.bench.renderer_specs import BenchGrid, read_grid
from rig.errors import RigError
from rig.render.direct import DirectRenderer
from rig.render.image_error import dssim, lab_error_percent, psnr_db, ssim
from rig.render.protocol import AppFrameRequest, DisplayFrameRequest, RenderSetup


ROW_FIELDS = (
    "renderer", "spec", "reconstruction", "views", "triangles", "width", "height", "rate_ratio",
    "frame_ms_median", "frame_ms_p95", "frame_gpu_ms_median", "frame_cpu_ms_median", "frames_timed", "client_ms_median",
    "primitives", "cost_source", "predictor", "photon_target",
    "latency_measured_ms", "latency_true_ms", "latency_sd_ms", "frame_delay_sd_ms", "missed_pct", "latency_period_s", "latency_note",
    "lab_error_pct", "ssim", "dssim", "psnr_db", "hole_pct", "timing", "machine", "failed",
)  # fmt: skip
"""A row's fields; `failed` says why its load could not be timed or its latency film failed (None: neither)."""
LATENCY_FIELDS = (
    "cost_source", "predictor", "photon_target", "latency_measured_ms", "latency_true_ms", "latency_sd_ms",
    "frame_delay_sd_ms", "missed_pct", "latency_period_s", "latency_note", "failed",
)  # fmt: skip
"""The fields a latency run fills in a row."""


def _percentile_ms(values: list[float], q: float) -> float | None:
    return float(np.percentile(values, q) * 1e3) if values else None


def time_direct(setup: RenderSetup, grid: BenchGrid) -> tuple[list[float], list[float]]:
    """Seconds per direct frame (render and readback; wall clock, and this process's CPU time): at
    least one frame, more within the budget; the first (which also compiles shaders) is dropped
    when three or more were timed."""
    renderer = DirectRenderer()
    renderer.open(setup)
    try:
        costs: list[float] = []
        cpu: list[float] = []
        pose = Pose(0.0, np.zeros(3), IDENTITY)
        while len(costs) < grid.direct_frames and (not costs or sum(costs) < grid.direct_budget_s):
            start = time.process_time()
            costs.append(renderer.render_app_frame(AppFrameRequest(len(costs), 0.0, 0.0, lambda t: pose)).cost_s)
            cpu.append(time.process_time() - start)
    finally:
        renderer.close()
    return (costs[1:], cpu[1:]) if len(costs) >= 3 else (costs, cpu)


def measure_warp_quality(measurement: WarpMeasurement, grid: BenchGrid) -> None:
    """Client frames at `grid.phases` swing phases, each warped up to max(ratios) refreshes ahead
    and compared with a direct render at the pose it was warped to. The client's cost drops the
    first frame (which also compiles shaders) when three or more were timed, as `time_direct` does."""
    renderer, pendulum = measurement.renderer, measurement.pendulum
    predict = pose_of(pendulum)
    for phase in range(grid.phases):
        t0 = (phase + 0.5) / grid.phases * pendulum.period_s
        index = measurement.next_frame
        measurement.next_frame += 1
        # photons a refresh after the start: a second view is predicted two refreshes ahead
        client = renderer.render_app_frame(AppFrameRequest(index, t0, t0 + 1.0 / grid.refresh_hz, predict))
        measurement.client_s.append(client.cost_s)
        for k in range(1, max(grid.ratios) + 1):
            t = t0 + k / grid.refresh_hz
            image = renderer.render_display_frame(DisplayFrameRequest(k, t, t, predict, index)).image
            reference = renderer.render_reference(pendulum.led_position(t), t)
            figures = (
                lab_error_percent(image, reference), ssim(image, reference), dssim(image, reference), psnr_db(image, reference),
                100.0 * renderer.hole_fraction(), float(renderer.last_primitives),
            )  # fmt: skip
            for ratio in grid.ratios:
                if k <= ratio:
                    measurement.errors[ratio].append(figures)
    if len(measurement.client_s) >= 3:
        measurement.client_s.pop(0)


def time_warp_rounds(measurements: list[WarpMeasurement], grid: BenchGrid) -> None:
    """Warp time per display frame, in rounds that visit every measurement in turn."""
    for round_ in range(grid.warp_rounds):
        for m in measurements:
            t = (round_ + 1) / grid.refresh_hz
            start = time.process_time()
            m.renderer.render_display_frame(DisplayFrameRequest(round_, t, t, pose_of(m.pendulum), m.next_frame - 1))
            m.cpu_s.append(time.process_time() - start)
            wall, gpu = m.renderer.last_warp_seconds
            m.wall_s.append(wall)
            if gpu is not None:
                m.gpu_s.append(gpu)


def warp_row(base: dict[str, Any], m: WarpMeasurement, triangles: int, size: tuple[int, int], ratio: int) -> dict[str, Any]:
    """A warp row: the renderer's costs and its image figures at one rate ratio."""
    options = m.renderer.options
    return {
        **base, "renderer": "warp", "spec": options.spec(), "reconstruction": options.recon, "views": options.views,
        "triangles": triangles, "width": size[0], "height": size[1], "rate_ratio": ratio,
        "frame_ms_median": _percentile_ms(m.wall_s, 50), "frame_ms_p95": _percentile_ms(m.wall_s, 95),
        "frame_gpu_ms_median": _percentile_ms(m.gpu_s, 50), "frame_cpu_ms_median": _percentile_ms(m.cpu_s, 50),
        "frames_timed": len(m.wall_s), "client_ms_median": _percentile_ms(m.client_s, 50), **m.quality(ratio),
        "timing": "wall clock until the GPU finished, no readback; frame_gpu_ms_median: GL timer query; "
        "frame_cpu_ms_median: this process's CPU time, all threads, with readback",
    }  # fmt: skip


def timed_load(
    grid: BenchGrid, size: tuple[int, int], triangles: int, base: dict[str, Any], log: Log
) -> tuple[dict[str, Any], WarpMeasurement, float]:
    """One load at one display size: its direct row, the warp renderer opened on it with its image
    error measured (the caller closes it, and times its rounds), and the direct frame's median (s)."""
    width, height = size
    setup, pendulum = scene_setup(width, height, triangles, grid.refresh_hz)
    started = time.perf_counter()
    direct, direct_cpu = time_direct(setup, grid)
    log(f"{width}x{height} {triangles:>9} triangles: direct {np.median(direct) * 1e3:9.1f} ms "
        f"({len(direct)} frames, {time.perf_counter() - started:.0f} s)")  # fmt: skip
    row = {
        **base, "renderer": "direct", "spec": "direct", "triangles": triangles, "width": width, "height": height,
        "frame_ms_median": _percentile_ms(direct, 50), "frame_ms_p95": _percentile_ms(direct, 95),
        "frame_cpu_ms_median": _percentile_ms(direct_cpu, 50), "frames_timed": len(direct),
        "timing": "wall clock, render and readback; frame_cpu_ms_median: this process's CPU time, all threads",
    }  # fmt: skip
    m = open_warp(grid.warp, setup, pendulum, grid.ratios)
    try:
        measure_warp_quality(m, grid)
    except BaseException:
        m.renderer.close()
        raise
    log(f"{width}x{height} {triangles:>9} triangles: warp client {np.median(m.client_s) * 1e3:9.1f} ms")
    return row, m, float(np.median(direct))


def run(grid: BenchGrid, context: Context) -> list[dict[str, Any]]:
    """Every row of the benchmark (see the module docstring). The timings run here, one at a time
    (a load that cannot be drawn is failed rows with the reason, and the others still run); the
    latency films (simulate, then analyse: a sweep into the context's folder) on its executor."""
    log = context.log
    warp_renderer(grid.warp)
    check_predictors(grid.predictor, grid.direct_predictor)
    machine = machine_name()
    log(f"machine: {machine}")
    rows: list[dict[str, Any]] = []
    expected: dict[tuple[str, int], tuple[float, float]] = {}
    base = dict.fromkeys(ROW_FIELDS)
    base["machine"] = machine
    for resolution_index, (width, height) in enumerate(grid.resolutions):
        measurements: list[WarpMeasurement] = []
        timed: list[int] = []
        try:
            for triangles in grid.triangles:
                try:
                    row, m, direct_s = timed_load(grid, (width, height), triangles, base, log)
                except RigError as error:
                    log(f"{width}x{height} {triangles:>9} triangles: failed: {error}")
                    rows += untimed_rows({**base, "triangles": triangles, "width": width, "height": height}, grid.warp, grid.ratios, str(error))
                    continue
                rows.append(row)
                measurements.append(m)
                timed.append(triangles)
                if resolution_index == 0 and triangles in (grid.latency_triangles or grid.triangles):
                    expected["direct", triangles] = (direct_s, 0.0)
                    expected["warp", triangles] = (float(np.median(m.client_s)), 0.0)
            time_warp_rounds(measurements, grid)
        finally:
            for m in measurements:
                m.renderer.close()
        for triangles, m in zip(timed, measurements):
            log(f"{width}x{height} {triangles:>9} triangles: warp {np.median(m.wall_s) * 1e3:7.1f} ms per display frame")
            if ("warp", triangles) in expected and resolution_index == 0:
                expected["warp", triangles] = (expected["warp", triangles][0], float(np.median(m.wall_s)))
            rows += [warp_row(base, m, triangles, (width, height), ratio) for ratio in grid.ratios]
    predictors = {"direct": grid.direct_predictor or grid.predictor, "warp": grid.predictor}
    films = [
        ({"renderer": renderer, "triangles": triangles},
         grid.latency_run(grid.warp if renderer == "warp" else renderer, triangles, predictors[renderer]), app_s, server_s)
        for (renderer, triangles), (app_s, server_s) in expected.items()
    ]  # fmt: skip
    comment = (f"The latency films of `rig bench renderers`, timed on {machine}.\n"
               "One renderer on one load each; the pendulum's period, the film's length and the camera's rate\n"
               "were chosen from the costs the timings measured. `rig sweep films.toml --out DIR` films them\n"
               "again, every cost measured again on the machine that runs it.")  # fmt: skip

    for (labels, *_), figures in zip(films, film_latencies(films, comment, context)):
        measured = figures["latency_measured_ms"]
        shown = f"{measured:.1f} ms measured, {figures['latency_true_ms']:.1f} ms true" if measured is not None else figures["latency_note"]
        if figures["failed"] is not None:
            shown = f"failed: {figures['failed']}"
        log(f"latency {labels['renderer']:6} {labels['triangles']:>9} triangles: {shown}")
        for row in rows:
            if (row["renderer"], row["triangles"], (row["width"], row["height"])) == (labels["renderer"], labels["triangles"], grid.resolutions[0]):
                row.update({name: figures[name] for name in LATENCY_FIELDS})
    return rows


def plain(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The rows as JSON holds them: an infinity or NaN (which JSON has not) as null."""
    return [{k: None if isinstance(v, float) and not math.isfinite(v) else v for k, v in row.items()} for row in rows]


GRID_OPTIONS = ("triangles", "resolutions", "ratios", "warp", "server_ms", "predictor", "direct_predictor")


def with_options(grid: BenchGrid, args: argparse.Namespace) -> BenchGrid:
    """`grid` with the grid's options given (GRID_OPTIONS) over it: the grid's, and each mode's."""
    return replace(grid, **given(args, *GRID_OPTIONS))


BENCH = Bench(
    spec=lambda args: with_options(args.spec, args), read_spec=read_grid,
    run=run, table=table, record=plain, plot=renderer_plots.plot_rows, all_failed=every_row_failed,
)
