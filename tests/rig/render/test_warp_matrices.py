"""The warp equations: per-object matrices, the Jacobian splat size, untracked-object extrapolation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from predictors import quaternion
from rig.render.warp_matrices import (
    UntrackedMotion,
    jacobian,
    pixel_ndc,
    pose_matrix,
    splat_size,
    translation,
    warp_matrix,
    widened_projection,
)

EYE = np.eye(4)


def perspective(fovy_deg: float, aspect: float, near: float, far: float) -> np.ndarray:
    f = 1.0 / np.tan(np.radians(fovy_deg) / 2.0)
    m = np.zeros((4, 4))
    m[0, 0], m[1, 1] = f / aspect, f
    m[2, 2], m[2, 3] = (far + near) / (near - far), 2.0 * far * near / (near - far)
    m[3, 2] = -1.0
    return m


def camera_at(z: float) -> np.ndarray:
    return translation([0.0, 0.0, -z])


unit_quaternions = st.lists(st.floats(-1.0, 1.0), min_size=4, max_size=4).filter(
    lambda q: np.linalg.norm(q) > 0.1
).map(lambda q: quaternion.normalise(np.array(q)))
positions = st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3).map(np.array)


@settings(max_examples=50, deadline=None)
@given(position=positions, orientation=unit_quaternions)
def test_a_server_pose_equal_to_the_client_pose_warps_nothing(position, orientation):
    """With S = C for object, camera and projection, M is the identity for any pose."""
    projection = perspective(60.0, 1.5, 0.1, 10.0)
    obj = pose_matrix(position, orientation)
    view = camera_at(3.0)
    np.testing.assert_allclose(warp_matrix(projection, view, obj, obj, view, projection), EYE, atol=1e-9)


def test_an_object_translation_moves_its_pixels_by_the_projected_offset():
    projection = np.diag([1 / 0.4, 1 / 0.3, -0.5, 1.0])
    client_obj, server_obj = translation([0.1, 0.0, 0.0]), translation([0.14, -0.03, 0.0])
    m = warp_matrix(projection, EYE, server_obj, client_obj, EYE, projection)
    ndc = np.array([0.25, 0.0, 0.0, 1.0])  # the client's pixel at the object's centre
    np.testing.assert_allclose(m @ ndc, [0.25 + 0.04 / 0.4, -0.03 / 0.3, 0.0, 1.0], atol=1e-12)


def test_the_jacobian_is_the_derivative_of_the_warp_after_division():
    rng = np.random.default_rng(7)
    projection = perspective(50.0, 4 / 3, 0.2, 5.0)
    m = warp_matrix(
        projection, camera_at(1.6), pose_matrix([0.1, 0.0, 0.3], quaternion.from_axis_angle([0, 1, 0], 0.3)),
        EYE, camera_at(2.0), projection,
    )
    points = np.column_stack([rng.uniform(-0.8, 0.8, (20, 2)), rng.uniform(0.3, 0.9, 20), np.ones(20)])
    slopes = rng.uniform(-0.5, 0.5, (20, 2))

    def warped_xy(p: np.ndarray) -> np.ndarray:
        q = p @ m.T
        return q[:, :2] / q[:, 3:4]

    h = 1e-6
    for b in range(2):
        step = np.zeros((20, 4))
        step[:, b] = h
        step[:, 2] = h * slopes[:, b]  # the depth follows the surface f(x, y)
        numeric = (warped_xy(points + step) - warped_xy(points - step)) / (2 * h)
        np.testing.assert_allclose(jacobian(m, points, slopes)[:, :, b], numeric, rtol=1e-5, atol=1e-7)


def test_splat_size_is_the_covering_square_in_whole_pixels():
    identity = np.eye(2)[np.newaxis]
    assert splat_size(identity, (100, 80), (100, 80), 8.0).tolist() == [1.0]
    # float rounding just above one pixel still makes a one-pixel splat
    assert splat_size(identity * (1 + 1e-7), (100, 80), (100, 80), 8.0).tolist() == [1.0]
    # 1.5x magnification: a 2-pixel splat; a 45-degree turn: extent sqrt(2) -> 2
    assert splat_size(identity * 1.5, (100, 80), (100, 80), 8.0).tolist() == [2.0]
    turn = np.array([[[np.cos(0.7854), -np.sin(0.7854)], [np.sin(0.7854), np.cos(0.7854)]]])
    assert splat_size(turn, (100, 80), (100, 80), 8.0).tolist() == [2.0]
    # the server has twice the pixels per NDC unit: a 2-pixel splat; huge magnification is capped
    assert splat_size(identity, (50, 40), (100, 80), 8.0).tolist() == [2.0]
    assert splat_size(identity * 40, (100, 80), (100, 80), 8.0).tolist() == [8.0]


def test_widened_projection_puts_client_pixel_centres_on_display_pixel_centres():
    world_to_clip = np.diag([1 / 0.4, 1 / 0.3, -0.5, 1.0])
    size, border = (64, 48), (4, 3)
    client = widened_projection(world_to_clip, size, border)
    m = warp_matrix(world_to_clip, EYE, EYE, EYE, EYE, client)
    cx, cy = pixel_ndc((size[0] + 2 * border[0], size[1] + 2 * border[1]))
    dx, dy = pixel_ndc(size)
    np.testing.assert_allclose(m[0, 0] * cx[border[0] : border[0] + size[0]] + m[0, 3], dx, atol=1e-12)
    np.testing.assert_allclose(m[1, 1] * cy[border[1] : border[1] + size[1]] + m[1, 3], dy, atol=1e-12)


def test_an_untracked_object_that_keeps_its_pose_does_not_move():
    motion = UntrackedMotion()
    for t in (0.0, 0.1, 0.2):
        motion.record(t, np.array([0.5, 0.0, 0.0]))
    assert not motion.moving
    np.testing.assert_array_equal(motion.pose_at(0.35).position, [0.5, 0.0, 0.0])


def test_an_untracked_object_is_extrapolated_linearly_and_by_slerp():
    """Constant velocity and turn rate: two client poses predict any later time exactly."""
    motion = UntrackedMotion()
    axis = np.array([0.0, 0.0, 1.0])
    for t in (0.0, 0.2):
        motion.record(t, np.array([1.0, 2.0, 0.0]) + t * np.array([0.5, -1.0, 0.25]), quaternion.from_axis_angle(axis, 1.5 * t))
    assert motion.moving
    pose = motion.pose_at(0.7)
    np.testing.assert_allclose(pose.position, [1.35, 1.3, 0.175], atol=1e-12)
    assert float(quaternion.angle_between(pose.orientation, quaternion.from_axis_angle(axis, 1.05))) == pytest.approx(0.0, abs=1e-9)
