"""How the rig's renderer frames a real pendulum: an orthographic view onto the plane it swings in.

A lab's tracker has its own axes, so the view is found from the motion: the first two principal
axes of the positions seen while the pendulum swings span the screen (the first across), centred on
their mean, the swing filling `SWING_FILL` of the width. The first axis points the way its larger
world component does (as the analyser orients the tracks), so the sphere moves across the screen
as the LED does across a camera that faces the same way as the tracker's axes; `mirror` turns the
screen's x round where the camera sees it the other way (a mirrored display reads as half a
swing period of extra latency).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rig.errors import RigError

SWING_FILL = 0.7
SPHERE_FRACTION = 0.04
"""The sphere's radius, as a share of the screen's width."""
MIN_SWING_M = 0.01


@dataclass(frozen=True)
class View:
    """What the renderer needs: world to clip space, and the sphere's radius in metres."""

    world_to_clip: np.ndarray
    sphere_radius_m: float


def view_from_positions(positions: np.ndarray, width: int, height: int, mirror: bool = False) -> View:
    """The view framing `positions` (N, 3, metres) seen during a swing on a width x height screen."""
    positions = np.asarray(positions, dtype=np.float64)
    if positions.ndim != 2 or positions.shape[1] != 3 or len(positions) < 10:
        raise RigError("framing the view needs at least ten tracker positions of the swinging pendulum")
    centre = positions.mean(axis=0)
    _, _, axes = np.linalg.svd(positions - centre, full_matrices=False)
    across, up = axes[0], axes[1]
    across = across if across[np.argmax(np.abs(across))] > 0 else -across
    up = up if up[np.argmax(np.abs(up))] > 0 else -up
    reach = float(np.max(np.abs((positions - centre) @ across)))
    if reach < MIN_SWING_M:
        raise RigError(
            f"the tracker moved only {reach * 1e3:.1f} mm while framing the view: release the pendulum before the run "
            "starts (or check that the tracker is on it)"
        )
    half_width = reach / SWING_FILL
    half_height = half_width * height / width
    normal = np.cross(across, up)
    sign = -1.0 if mirror else 1.0
    world_to_clip = np.eye(4)
    world_to_clip[0, :3], world_to_clip[0, 3] = sign * across / half_width, -sign * across @ centre / half_width
    world_to_clip[1, :3], world_to_clip[1, 3] = up / half_height, -up @ centre / half_height
    world_to_clip[2, :3], world_to_clip[2, 3] = -normal / (4.0 * half_width), normal @ centre / (4.0 * half_width)
    return View(world_to_clip, SPHERE_FRACTION * 2.0 * half_width)
