"""What a simulated run will take before it starts, so that a run that cannot finish is refused in one
line with its estimate: every setting may be within its range while their product (a long film at a
high rate, a heavy scene drawn many times) is days of work."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rig.sim.config import SimulationConfig

PIXEL_INSTANTS_PER_S = 1e9
"""Sensor pixels the simulated camera films per second, one exposure instant each: a generous
rate (this machine films about 8e8)."""
TRIANGLES_PER_S = 1e9
"""Load triangles the renderer draws per second: a generous rate for a GPU."""
MAX_HOURS = 24.0
"""The longest simulation the rig starts: longer is a mistake in the settings, not a lab's run."""


def estimated_hours(config: SimulationConfig) -> float:
    """Hours the run takes at the generous rates above: its film's pixel-instants and its scene's
    triangles, drawn at most once a refresh and at least once an application frame."""
    camera = config.camera
    filming_s = config.duration_s * camera.fps * camera.width * camera.height * camera.subsamples / PIXEL_INSTANTS_PER_S
    frame_s = (config.app_frame_ms or 0.0) / 1e3
    frames_per_s = config.display.refresh_hz if frame_s == 0.0 else min(config.display.refresh_hz, 1.0 / frame_s)
    drawing_s = (config.duration_s + config.warmup_s) * frames_per_s * config.scene_triangles / TRIANGLES_PER_S
    return (filming_s + drawing_s) / 3600.0


def problem(config: SimulationConfig) -> str | None:
    """A sentence saying the run cannot finish, with its estimate, or None."""
    hours = estimated_hours(config)
    if hours <= MAX_HOURS:
        return None
    camera = config.camera
    return (
        f"this run would take about {hours:.3g} hours ({config.duration_s:g} s filmed at {camera.fps:g} fps, "
        f"{camera.width}x{camera.height} pixels, {camera.subsamples} instants an exposure, {config.scene_triangles} "
        f"load triangles), more than the {MAX_HOURS:g} hours the rig starts: film shorter, slower, smaller or "
        f"with fewer triangles"
    )
