"""How long a renderer bench grid would take at the least (`estimated_hours`), so that a grid that
cannot finish is refused with its estimate before any frame is drawn.

The figures are generous on purpose (the fastest GPUs' rates): the estimate is a floor, so only a
grid that no machine finishes within `rig.sim.config.MAX_HOURS` is refused. Each load at each
resolution is drawn for its direct frames (at most the direct budget of time), its client frames
and warps for the image error (`phases` poses, each warped at every ratio), and its warp rounds;
each latency film renders its load at the display's refresh for at least its duration.
"""

from __future__ import annotations

from typing import Any

TRIANGLES_PER_S = 1e9
"""Triangles a second the fastest GPU draws in small random triangles."""
PIXELS_PER_S = 1e10
"""Pixels a second the fastest GPU warps and reads back."""
FILMED_RENDERERS = 2
"""Each filmed load is filmed through the direct and the warp renderer."""


def estimated_hours(grid: Any) -> float:
    """The least time the `rig.bench.renderers.BenchGrid` `grid` takes, in hours (module docstring)."""
    seconds = 0.0
    for width, height in grid.resolutions:
        for triangles in grid.triangles:
            frame_s = triangles / TRIANGLES_PER_S
            direct_s = min(grid.direct_budget_s, grid.direct_frames * frame_s)
            image_error_s = grid.phases * (frame_s + len(grid.ratios) * width * height / PIXELS_PER_S)
            rounds_s = grid.warp_rounds * (frame_s + width * height / PIXELS_PER_S)
            seconds += direct_s + image_error_s + rounds_s
    filmed = grid.latency_triangles if grid.latency_triangles is not None else grid.triangles
    film_frames = grid.latency_duration_s * grid.refresh_hz
    seconds += FILMED_RENDERERS * sum(film_frames * triangles / TRIANGLES_PER_S for triangles in filmed)
    return seconds / 3600.0
