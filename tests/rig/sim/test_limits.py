"""Every number a user sets is bounded (a finite range declared on it), and a simulated run's
settings' product is bounded too: a run whose estimate is past `MAX_HOURS` is refused before it starts."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from declared import walk
from declared.settings import optional
from rig.errors import ConfigError
from rig.option_tables import SECTIONS
from rig.sim.camera import CameraConfig
from rig.sim.config import MAX_HOURS, PIXEL_INSTANTS_PER_S, SimulationConfig
from rig.sim.display import DisplayConfig

NUMBERS = (int, float)


def _numeric(hint: object) -> bool:
    inner, _ = optional(hint)
    args = getattr(inner, "__args__", (inner,))
    return all(arg in NUMBERS or arg is Ellipsis for arg in args)


def _bounded(end: float, included: bool) -> bool:
    """An end is finite, or infinite only where it is a value (a Q factor of inf: no damping)."""
    return math.isfinite(end) or included


DECLARING = tuple(kind for _, kind, _, _ in SECTIONS)
"""Every config whose settings a user gives: the docs' tables' (`rig.option_tables`)."""


@pytest.mark.parametrize(
    "entry", [e for kind in DECLARING for e in walk(kind) if _numeric(e.hint)], ids=lambda e: f"{e.path}"
)
def test_every_numeric_setting_has_a_finite_range(entry: object) -> None:
    declared = entry.setting
    assert declared.range is not None, entry.path
    assert _bounded(declared.range.low, declared.range.includes_low), entry.path
    assert _bounded(declared.range.high, declared.range.includes_high), entry.path


def test_the_default_run_is_far_inside_the_limit() -> None:
    assert SimulationConfig().estimated_hours() < 0.01 * MAX_HOURS


@given(st.floats(0.5, 1800.0), st.floats(1.0, 5000.0))
def test_filming_hours_are_frames_times_pixel_instants(duration_s: float, fps: float) -> None:
    camera = CameraConfig(fps=fps, width=64, height=48, subsamples=1)
    config = SimulationConfig(duration_s=duration_s, camera=camera)
    assert config.estimated_hours() == pytest.approx(duration_s * fps * 64 * 48 / PIXEL_INSTANTS_PER_S / 3600.0)


def test_a_run_that_cannot_finish_is_refused_with_its_estimate() -> None:
    with pytest.raises(ConfigError, match=r"about 24\.6 hours \(3600 s filmed at 10000 fps, 640x480 pixels.*more than the 24 hours"):
        SimulationConfig(duration_s=3600.0, camera=CameraConfig(fps=10000.0))


def test_a_heavy_scene_drawn_for_an_hour_is_refused() -> None:
    with pytest.raises(ConfigError, match="100000000 load triangles"):
        SimulationConfig(duration_s=3600.0, scene_triangles=100_000_000, app_frame_ms=1.0, display=DisplayConfig(refresh_hz=1000.0))
