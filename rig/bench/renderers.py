"""The renderer bench (`rig bench renderers`): cost, latency and image error of the direct and the warp renderer against scene size.

For each display resolution and load of N triangles:

* direct: the real frame time on this machine (render and readback, wall clock);
* warp: the client's frame time, the server's warp time per display frame (wall clock until the
  GPU has finished, without readback, and the GL timer query beside it), timed in rounds that
  interleave all N so that a drift in machine load touches every N alike; and the image error of
  warped frames against a direct render at the same pose. For a client:display rate ratio of 1:r,
  a client frame drawn at the pendulum's pose at t0 is warped to its poses at t0 + k refreshes,
  k = 1..r (the seeds' synchronised client-server mode), at several phases of the swing; the
  figures are the means over all of them: the percentage of pixels whose CIE Lab distance
  exceeds 10 after a 3-pixel Gaussian blur, PSNR, and the percentage of level-0 hole pixels.

Both also report this process's CPU time per frame (all threads, readback included): on a machine
shared with other work, wall times carry their load, CPU times hardly.

Latency: a real frame of a few million triangles takes seconds in software OpenGL, so the frame
costs measured at the first resolution are then modelled on the simulation's virtual clock ("cost
measured, then modelled"), the server at the session's modelled warp cost; the simulated display is
small to keep the per-refresh warps affordable. The pendulum's period is stretched so the expected
latency stays under LATENCY_PERIOD_FRACTION of it (the analyser resolves latency only modulo a
period); a latency that would need a period over the grid's limit is reported as beyond range.
"""

from __future__ import annotations

import os
import platform
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Callable

import numpy as np

import analysis
from analysis import AnalysisError
from predictors import Pose
from rig.render import gl
from rig.render.direct import DirectRenderer
from rig.render.image_error import lab_error_percent, psnr_db
from rig.render.protocol import AppFrameRequest, DisplayFrameRequest, RenderSetup
from rig.render.warp import WarpRenderer
from rig.service import SimulationConfig, simulate
from rig.session import DEFAULT_SERVER_MS
from rig.sim.bench import make_layout
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import Pendulum, PendulumConfig

LATENCY_PERIOD_FRACTION = 0.3
"""The pendulum period is at least the expected latency over this fraction (well below one half)."""
CAMERA_FRAMES_PER_PERIOD = 240.0
"""Camera frames per swing period in the latency runs (at most 240 fps, at least MIN_CAMERA_FPS)."""
MIN_CAMERA_FPS = 60.0
LATENCY_PERIODS = 3.0
"""Swing periods filmed in a latency run at least (the analyser needs two)."""
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])

ROW_FIELDS = (
    "renderer", "reconstruction", "views", "triangles", "width", "height", "rate_ratio",
    "frame_ms_median", "frame_ms_p95", "frame_gpu_ms_median", "frame_cpu_ms_median", "frames_timed", "client_ms_median",
    "latency_measured_ms", "latency_true_ms", "latency_sd_ms", "latency_period_s", "latency_note",
    "lab_error_pct", "psnr_db", "hole_pct", "timing", "machine",
)  # fmt: skip


@dataclass(frozen=True)
class BenchGrid:
    """What `rig bench renderers` measures, and how much of it."""

    triangles: tuple[int, ...] = (10_000, 100_000, 1_000_000, 5_000_000)
    resolutions: tuple[tuple[int, int], ...] = ((640, 480), (1280, 720))
    ratios: tuple[int, ...] = (1, 5, 10)
    phases: int = 4
    """client poses per (N, resolution) for the image error, spread over a swing"""
    warp_rounds: int = 16
    direct_frames: int = 4
    direct_budget_s: float = 6.0
    """stop timing direct frames (after the first) once this much time is spent"""
    latency_triangles: tuple[int, ...] | None = None
    """the load sizes whose latency is simulated (None: all)"""
    latency_display: tuple[int, int] = (320, 240)
    latency_camera: CameraConfig = CameraConfig()
    """the latency runs' camera; its frame rate follows the pendulum period"""
    latency_duration_s: float = 6.0
    max_period_s: float = 8.0
    refresh_hz: float = 60.0


QUICK_GRID = BenchGrid(
    triangles=(1_000, 8_000),
    resolutions=((160, 120),),
    ratios=(1, 3),
    phases=1,
    warp_rounds=3,
    direct_frames=3,
    direct_budget_s=1.0,
    latency_triangles=(1_000,),
    latency_display=(160, 120),
    latency_camera=CameraConfig(width=320, height=240, subsamples=4),
    latency_duration_s=2.5,
    max_period_s=4.0,
)

Log = Callable[[str], None]


def _percentile_ms(values: list[float], q: float) -> float | None:
    return float(np.percentile(values, q) * 1e3) if values else None


def machine_name() -> str:
    """CPU, core count and OpenGL renderer of this machine, for the record."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    ctx = gl.create_context()
    try:
        gl_name = f"{ctx.info['GL_RENDERER']}, OpenGL {ctx.version_code // 100}.{ctx.version_code % 100 // 10}"
    finally:
        ctx.release()
    return f"{cpu}, {os.cpu_count()} cores, {gl_name}"


def _setup(width: int, height: int, triangles: int, refresh_hz: float) -> tuple[RenderSetup, Pendulum]:
    """The session's view of the default pendulum at this display size, costs measured."""
    pendulum = Pendulum(PendulumConfig(), t_end=3.0)
    layout = make_layout(pendulum, CameraConfig(), DisplayConfig(refresh_hz=refresh_hz, width=width, height=height))
    setup = RenderSetup(width, height, layout.world_to_clip, layout.sphere_radius_m, scene_triangles=triangles)
    return setup, pendulum


def _pose_of(pendulum: Pendulum) -> Callable[[float], Pose]:
    """The pendulum's exact pose at any time: prediction error stays out of the image error."""
    return lambda t: Pose(t, pendulum.led_position(t), IDENTITY)


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


@dataclass
class _WarpMeasurement:
    renderer: WarpRenderer
    pendulum: Pendulum
    client_s: list[float]
    errors: dict[int, list[tuple[float, float, float]]]
    wall_s: list[float]
    gpu_s: list[float]
    cpu_s: list[float]
    next_frame: int = 0


def measure_warp_quality(measurement: _WarpMeasurement, grid: BenchGrid) -> None:
    """Client frames at `grid.phases` swing phases, each warped up to max(ratios) refreshes ahead
    and compared with a direct render at the pose it was warped to. The client's cost drops the
    first frame (which also compiles shaders) when three or more were timed, as `time_direct` does."""
    renderer, pendulum = measurement.renderer, measurement.pendulum
    predict = _pose_of(pendulum)
    for phase in range(grid.phases):
        t0 = (phase + 0.5) / grid.phases * pendulum.period_s
        index = measurement.next_frame
        measurement.next_frame += 1
        client = renderer.render_app_frame(AppFrameRequest(index, t0, t0, predict))
        measurement.client_s.append(client.cost_s)
        for k in range(1, max(grid.ratios) + 1):
            t = t0 + k / grid.refresh_hz
            image = renderer.render_display_frame(DisplayFrameRequest(k, t, t, predict, index)).image
            reference = renderer.render_reference(pendulum.led_position(t))
            figures = (lab_error_percent(image, reference), psnr_db(image, reference), 100.0 * renderer.hole_fraction())
            for ratio in grid.ratios:
                if k <= ratio:
                    measurement.errors[ratio].append(figures)
    if len(measurement.client_s) >= 3:
        measurement.client_s.pop(0)


def time_warp_rounds(measurements: list[_WarpMeasurement], grid: BenchGrid) -> None:
    """Warp time per display frame, in rounds that visit every N in turn."""
    for round_ in range(grid.warp_rounds):
        for m in measurements:
            t = (round_ + 1) / grid.refresh_hz
            start = time.process_time()
            m.renderer.render_display_frame(DisplayFrameRequest(round_, t, t, _pose_of(m.pendulum), m.next_frame - 1))
            m.cpu_s.append(time.process_time() - start)
            wall, gpu = m.renderer.last_warp_seconds
            m.wall_s.append(wall)
            if gpu is not None:
                m.gpu_s.append(gpu)


def measure_latency(
    renderer: str, triangles: int, cost_s: float, grid: BenchGrid, predictor: str, out_dir: Path
) -> dict[str, Any]:
    """Simulate the rig with `cost_s` modelled per application frame, analyse its video.

    Returns the measured and true latency (ms), the spread of the per-display-frame delay, the
    period used, and a note; latencies are None when the expected one needs too long a period.
    """
    server_s = DEFAULT_SERVER_MS / 1e3 if renderer == "warp" else 0.0
    expected_s = (2.0 * cost_s if renderer == "direct" else server_s) + 0.1
    period = max(PendulumConfig().period_s, expected_s / LATENCY_PERIOD_FRACTION)
    if period > grid.max_period_s:
        return {
            "latency_period_s": None,
            "latency_note": f"beyond range: about {expected_s:.1f} s expected, which needs a pendulum period over "
            f"{grid.max_period_s:g} s",
        }
    width, height = grid.latency_display
    config = SimulationConfig(
        duration_s=max(grid.latency_duration_s, LATENCY_PERIODS * period),
        pendulum=PendulumConfig(period_s=period),
        display=DisplayConfig(refresh_hz=grid.refresh_hz, width=width, height=height),
        camera=replace(grid.latency_camera, fps=min(240.0, max(MIN_CAMERA_FPS, CAMERA_FRAMES_PER_PERIOD / period))),
        renderer=renderer,
        predictor=predictor,
        scene_triangles=triangles,
        app_frame_ms=cost_s * 1e3,
        # the first frame must be on show when filming starts; and the truth's latency search looks
        # up to about a period back, which the session's pendulum covers only within its warm-up
        warmup_s=max(cost_s + 0.5, period),
    )
    run = simulate(config, out_dir, overwrite=True)
    server = f", server {DEFAULT_SERVER_MS:g} ms modelled" if renderer == "warp" else ""
    note = (
        f"cost measured, then modelled: {cost_s * 1e3:.1f} ms per application frame{server}; "
        f"simulated at {width}x{height}, predictor {predictor}"
    )
    figures = {
        "latency_measured_ms": None,
        "latency_true_ms": run.truth.latency_ms,
        "latency_sd_ms": run.truth.display_frame_delay_ms.sd,
        "latency_period_s": period,
    }
    try:
        # the ROIs of the simulated bench, as a lab marks them once for its camera
        result = analysis.analyse(run.video_path, led_roi=run.truth.led_roi, sphere_roi=run.truth.sphere_roi)
    except AnalysisError as error:
        return {**figures, "latency_note": f"{note}; the analyser failed: {error}"}
    if result.ambiguous:
        note += "; AMBIGUOUS (near half a period)"
    return {**figures, "latency_measured_ms": result.latency_ms, "latency_note": note}


def run_bench(grid: BenchGrid, predictors: dict[str, str], runs_dir: Path, log: Log) -> list[dict[str, Any]]:
    """Every row of the benchmark (see the module docstring); `predictors` names each renderer's
    predictor in the latency runs."""
    machine = machine_name()
    log(f"machine: {machine}")
    rows: list[dict[str, Any]] = []
    costs_for_latency: dict[tuple[str, int], float] = {}
    base = dict.fromkeys(ROW_FIELDS)
    base["machine"] = machine
    for resolution_index, (width, height) in enumerate(grid.resolutions):
        measurements: list[_WarpMeasurement] = []
        try:
            for triangles in grid.triangles:
                setup, pendulum = _setup(width, height, triangles, grid.refresh_hz)
                started = time.perf_counter()
                direct, direct_cpu = time_direct(setup, grid)
                log(f"{width}x{height} {triangles:>9} triangles: direct {np.median(direct) * 1e3:9.1f} ms "
                    f"({len(direct)} frames, {time.perf_counter() - started:.0f} s)")  # fmt: skip
                rows.append({
                    **base, "renderer": "direct", "triangles": triangles, "width": width, "height": height,
                    "frame_ms_median": _percentile_ms(direct, 50), "frame_ms_p95": _percentile_ms(direct, 95),
                    "frame_cpu_ms_median": _percentile_ms(direct_cpu, 50), "frames_timed": len(direct),
                    "timing": "wall clock, render and readback; frame_cpu_ms_median: this process's CPU time, all threads",
                })  # fmt: skip
                renderer = WarpRenderer()
                renderer.open(setup)
                m = _WarpMeasurement(renderer, pendulum, [], {r: [] for r in grid.ratios}, [], [], [])
                measurements.append(m)
                measure_warp_quality(m, grid)
                log(f"{width}x{height} {triangles:>9} triangles: warp client {np.median(m.client_s) * 1e3:9.1f} ms")
                if resolution_index == 0 and triangles in (grid.latency_triangles or grid.triangles):
                    costs_for_latency["direct", triangles] = float(np.median(direct))
                    costs_for_latency["warp", triangles] = float(np.median(m.client_s))
            time_warp_rounds(measurements, grid)
        finally:
            for m in measurements:
                m.renderer.close()
        for triangles, m in zip(grid.triangles, measurements):
            log(f"{width}x{height} {triangles:>9} triangles: warp {np.median(m.wall_s) * 1e3:7.1f} ms per display frame")
            for ratio in grid.ratios:
                lab, psnr, holes = np.array(m.errors[ratio]).T
                finite_psnr = psnr[np.isfinite(psnr)]
                rows.append({
                    **base, "renderer": "warp", "reconstruction": m.renderer.reconstruction, "views": m.renderer.views,
                    "triangles": triangles, "width": width, "height": height, "rate_ratio": ratio,
                    "frame_ms_median": _percentile_ms(m.wall_s, 50), "frame_ms_p95": _percentile_ms(m.wall_s, 95),
                    "frame_gpu_ms_median": _percentile_ms(m.gpu_s, 50), "frame_cpu_ms_median": _percentile_ms(m.cpu_s, 50),
                    "frames_timed": len(m.wall_s),
                    "client_ms_median": _percentile_ms(m.client_s, 50),
                    "lab_error_pct": float(lab.mean()),
                    "psnr_db": float(finite_psnr.mean()) if len(finite_psnr) else None,
                    "hole_pct": float(holes.mean()),
                    "timing": "wall clock until the GPU finished, no readback; frame_gpu_ms_median: GL timer query; "
                    "frame_cpu_ms_median: this process's CPU time, all threads, with readback",
                })  # fmt: skip
    first = grid.resolutions[0]
    for (renderer, triangles), cost in costs_for_latency.items():
        started = time.perf_counter()
        figures = measure_latency(renderer, triangles, cost, grid, predictors[renderer], runs_dir / f"{renderer}-{triangles}")
        measured = figures.get("latency_measured_ms")
        shown = f"{measured:.1f} ms measured, {figures['latency_true_ms']:.1f} ms true" if measured is not None else figures["latency_note"]
        log(f"latency {renderer:6} {triangles:>9} triangles: {shown} ({time.perf_counter() - started:.0f} s)")
        for row in rows:
            if (row["renderer"], row["triangles"], (row["width"], row["height"])) == (renderer, triangles, first):
                row.update(figures)
    return rows
