"""The warp equations of the seed architecture (Smit et al. 2010, sections 3.2 and 3.4), in numpy.

A client pixel at NDC position (x, y) with NDC depth z = f(x, y), showing object i, goes to the
server's clip-space position P' = M_i (x, y, z, 1), where

    M_i = S_proj_i S_view S_obj_i inverse(C_obj_i) inverse(C_view) inverse(C_proj_i):

unproject with the client's projection and camera, undo the client's object matrix, apply the
server's newest object matrix, and project with the server's camera and projection. A projection
may differ per object (here: the depth partition that keeps the tracked sphere in front of the load,
see `rig.render.gl`), as long as client and server use the same one for that object.

The splat covering a warped pixel follows from the Jacobian of the warp after the homogeneous
division (section 3.4): with M_n the n-th column of M and f_x, f_y the depth slopes,

    d(P'_a / P'_w) / dx = (P'_w (M_a0 + M_a2 f_x) - P'_a (M_w0 + M_w2 f_x)) / P'_w^2

and likewise for y. The point splat is the smallest screen-aligned square of whole pixels that
covers the warped pixel's parallelogram (the seeds' `ceil(max(...))`, with absolute values so the
square covers a mirrored or rotated pixel too).
"""

from __future__ import annotations

import numpy as np

import predictors
from predictors import Pose, PoseSample, quaternion

SPLAT_ROUNDING = 1e-4
"""A splat extent this close above a whole number of pixels counts as that number: float rounding
in the matrices must not turn an exact one-pixel splat into a two-pixel one."""

_IDENTITY_ORIENTATION = np.array([1.0, 0.0, 0.0, 0.0])


def translation(position: np.ndarray) -> np.ndarray:
    """The 4x4 matrix that moves points by `position` (3,)."""
    m = np.eye(4)
    m[:3, 3] = np.asarray(position, dtype=np.float64)
    return m


def pose_matrix(position: np.ndarray, orientation: np.ndarray = _IDENTITY_ORIENTATION) -> np.ndarray:
    """The 4x4 body-to-world matrix of a pose: rotate by `orientation` (w, x, y, z), then translate."""
    m = translation(position)
    m[:3, :3] = quaternion.to_matrix(orientation)
    return m


def warp_matrix(
    server_projection: np.ndarray,
    server_view: np.ndarray,
    server_object: np.ndarray,
    client_object: np.ndarray,
    client_view: np.ndarray,
    client_projection: np.ndarray,
) -> np.ndarray:
    """M = S_proj S_view S_obj inverse(C_obj) inverse(C_view) inverse(C_proj), all 4x4 float64."""
    client = client_projection @ client_view @ client_object
    return server_projection @ server_view @ server_object @ np.linalg.inv(client)


def widened_projection(world_to_clip: np.ndarray, size: tuple[int, int], border: tuple[int, int]) -> np.ndarray:
    """`world_to_clip` seeing `border` = (bx, by) more pixels on every side of a `size` = (w, h) view.

    The client renders (w + 2 bx) x (h + 2 by) pixels at the display's pixel density, so its pixel
    (i, j) lies exactly on display pixel (i - bx, j - by): warping to the client's own pose maps
    pixel centres onto pixel centres.
    """
    (w, h), (bx, by) = size, border
    scale = np.diag([w / (w + 2.0 * bx), h / (h + 2.0 * by), 1.0, 1.0])
    return scale @ np.asarray(world_to_clip, dtype=np.float64)


def pixel_ndc(size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """NDC x (w,) and y (h,) of the pixel centres of a `size` = (w, h) image, y up (OpenGL rows)."""
    w, h = size
    return (np.arange(w) + 0.5) / w * 2.0 - 1.0, (np.arange(h) + 0.5) / h * 2.0 - 1.0


def jacobian(matrix: np.ndarray, points: np.ndarray, depth_slope: np.ndarray) -> np.ndarray:
    """d(P'_xy / P'_w) / d(x, y) for client points (N, 4) = (x, y, f, 1) warped by `matrix` (4, 4).

    `depth_slope` (N, 2) is (df/dx, df/dy) in NDC per NDC. Returns (N, 2, 2) with [n, a, b] the
    derivative of warped coordinate a by client coordinate b.
    """
    m = np.asarray(matrix, dtype=np.float64)
    p = points @ m.T
    d = m[:, 0:2][np.newaxis, :, :] + m[:, 2][np.newaxis, :, np.newaxis] * depth_slope[:, np.newaxis, :]
    w = p[:, 3][:, np.newaxis, np.newaxis]
    return (w * d[:, 0:2, :] - p[:, 0:2, np.newaxis] * d[:, 3:4, :]) / w**2


def splat_size(
    jacobian_ndc: np.ndarray, client_size: tuple[int, int], server_size: tuple[int, int], max_size: float
) -> np.ndarray:
    """Point-splat side in whole server pixels for Jacobians (N, 2, 2) taken in NDC per NDC.

    In pixels the Jacobian is J[a, b] * server_size[a] / client_size[b]; the splat is the ceiling
    of the larger extent of the warped pixel, |J_a0| + |J_a1| over a = x, y, at least 1 and at
    most `max_size`.
    """
    scale = np.asarray(server_size, dtype=np.float64)[:, np.newaxis] / np.asarray(client_size, dtype=np.float64)[np.newaxis, :]
    extent = (np.abs(jacobian_ndc) * scale).sum(axis=2).max(axis=1)
    return np.clip(np.ceil(extent - SPLAT_ROUNDING), 1.0, max_size)


class UntrackedMotion:
    """The server pose of an object not bound to the tracker, from its client poses (section 3.2).

    The server keeps the object's poses from the last two client frames and extrapolates them to
    each display frame: slerp on rotation, linear on translation (the `slerp` predictor does both).
    An object whose last two client poses are equal does not move: `moving` is False and the
    server keeps its cached warp matrix instead of building a new one.
    """

    def __init__(self) -> None:
        self._extrapolator = predictors.make("slerp")
        self._newest: tuple[float, np.ndarray, np.ndarray] | None = None
        self.moving = False

    def record(self, t: float, position: np.ndarray, orientation: np.ndarray = _IDENTITY_ORIENTATION) -> None:
        """Remember the pose a client frame drew the object in, for the time `t` that frame shows."""
        position = np.asarray(position, dtype=np.float64)
        orientation = quaternion.normalise(orientation)
        if self._newest is not None:
            _, last_position, last_orientation = self._newest
            self.moving = not (
                np.array_equal(position, last_position)
                and float(quaternion.angle_between(orientation, last_orientation)) == 0.0
            )
        self._newest = (float(t), position, orientation)
        self._extrapolator.update(PoseSample(t_sensor=float(t), t_arrival=float(t), position=position, orientation=orientation))

    def pose_at(self, t: float) -> Pose:
        """The extrapolated pose at `t`; the newest client pose while fewer than two are known."""
        return self._extrapolator.predict(t)
