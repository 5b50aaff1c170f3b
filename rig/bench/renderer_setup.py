"""What the renderer benches measure on: this machine, the pendulum scene at a display size with
its load, and an open warp renderer with what has been measured of it."""

from __future__ import annotations

import os
import platform
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from predictors import Pose
from rig.errors import ConfigError
from rig.render import gl, make_renderer
from rig.render.protocol import RenderSetup
from rig.render.warp import WarpRenderer
from rig.sim.layout import make_layout
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import Pendulum, PendulumConfig

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


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


def scene_setup(width: int, height: int, triangles: int, refresh_hz: float, load: str = "soup") -> tuple[RenderSetup, Pendulum]:
    """The session's view of the default pendulum at this display size, costs measured, with a
    load of `triangles` shaped as `load` says (`rig.render.gl.LOAD_SHAPES`)."""
    pendulum = Pendulum(PendulumConfig(), t_end=3.0)
    layout = make_layout(pendulum, CameraConfig(), DisplayConfig(refresh_hz=refresh_hz, width=width, height=height))
    setup = RenderSetup(width, height, layout.world_to_clip, layout.sphere_radius_m, scene_triangles=triangles, scene_load=load)
    return setup, pendulum


def pose_of(pendulum: Pendulum) -> Callable[[float], Pose]:
    """The pendulum's exact pose at any time: prediction error stays out of the image error."""
    return lambda t: Pose(t, pendulum.led_position(t), IDENTITY)


QUALITY_FIGURES = ("lab_error_pct", "ssim", "dssim", "psnr_db", "hole_pct", "primitives")


@dataclass
class WarpMeasurement:
    """One open warp renderer on a pendulum scene, and what was measured of it: client seconds,
    per rate ratio the image figures (QUALITY_FIGURES) of every warped frame, and per timed display
    frame its wall, GL-query and CPU seconds."""

    renderer: WarpRenderer
    pendulum: Pendulum
    client_s: list[float] = field(default_factory=list)
    errors: dict[int, list[tuple[float, ...]]] = field(default_factory=dict)
    wall_s: list[float] = field(default_factory=list)
    gpu_s: list[float] = field(default_factory=list)
    cpu_s: list[float] = field(default_factory=list)
    next_frame: int = 0

    def quality(self, ratio: int) -> dict[str, float | None]:
        """The mean of each image figure at client:display rate ratio 1:`ratio` (PSNR over finite values)."""
        values = np.array(self.errors[ratio], dtype=np.float64)
        means: dict[str, float | None] = {}
        for name, column in zip(QUALITY_FIGURES, values.T):
            finite = column[np.isfinite(column)]
            means[name] = float(finite.mean()) if len(finite) else None
        return means


def warp_renderer(spec: str) -> WarpRenderer:
    """The warp renderer of `spec`, not yet open; ConfigError where `spec` is not one (a bench checks
    its specs so before any work: a typo is refused, not a row failed after the timings)."""
    renderer = make_renderer(spec)
    if not isinstance(renderer, WarpRenderer):
        raise ConfigError(f"the renderer bench's warp spec must be a warp renderer, got {spec!r}")
    return renderer


def open_warp(spec: str, setup: RenderSetup, pendulum: Pendulum, ratios: tuple[int, ...]) -> WarpMeasurement:
    """The warp renderer of `spec`, open on `setup`."""
    renderer = warp_renderer(spec)
    renderer.open(setup)
    return WarpMeasurement(renderer, pendulum, errors={r: [] for r in ratios})
