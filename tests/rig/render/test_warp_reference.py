"""The numpy reference warp: pixels land where the matrices send them, nearest first, splats sized."""

from __future__ import annotations

import numpy as np

from tests.rig.render.warp_reference import depth_slopes, reference_warp
from rig.render.warp_server import BACKGROUND_NDC_Z

W, H = 12, 10


def client_images(seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    colour = rng.integers(0, 256, (H, W, 4), dtype=np.uint8)
    ids = np.ones((H, W), dtype=np.int64)
    depth = rng.uniform(0.2, 0.8, (H, W)).astype(np.float32)
    return colour, ids, depth


def ndc_shift(dx_px: float, dy_px: float) -> np.ndarray:
    m = np.eye(4)
    m[0, 3], m[1, 3] = 2.0 * dx_px / W, 2.0 * dy_px / H
    return m


def test_identity_matrices_reproduce_the_client_image():
    colour, ids, depth = client_images()
    out, out_depth = reference_warp(colour, ids, depth, np.stack([np.eye(4)] * 2), (W, H), 8.0, BACKGROUND_NDC_Z)
    np.testing.assert_array_equal(out[:, :, :3], colour[:, :, :3])
    assert (out[:, :, 3] == 255).all()
    np.testing.assert_allclose(out_depth, depth, atol=1e-6)


def test_a_whole_pixel_translation_moves_every_pixel_and_leaves_a_hole_strip():
    colour, ids, depth = client_images()
    out, _ = reference_warp(colour, ids, depth, np.stack([np.eye(4), ndc_shift(3, -2)]), (W, H), 8.0, BACKGROUND_NDC_Z)
    np.testing.assert_array_equal(out[0 : H - 2, 3:, :3], colour[2:, : W - 3, :3])
    covered = out[:, :, 3] == 255
    assert not covered[:, :3].any() and not covered[H - 2 :, :].any()
    assert covered[: H - 2, 3:].all()


def test_the_nearer_of_two_pixels_landing_on_one_wins_and_equal_depths_keep_the_first_drawn():
    colour, ids, depth = client_images()
    ids[:, 6:] = 0  # the right half is background, warped just inside the far plane
    depth[:, :] = 0.5
    # object 1 (left half) moves right onto the background half
    out, _ = reference_warp(colour, ids, depth, np.stack([np.eye(4), ndc_shift(6, 0)]), (W, H), 8.0, BACKGROUND_NDC_Z)
    np.testing.assert_array_equal(out[:, 6:, :3], colour[:, :6, :3])
    # two copies of the same pixel at one depth: the first drawn (lower pixel index) stays
    ids[:, :] = 1
    colour2, _, _ = client_images(1)
    flat = np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    squash = flat.copy()
    squash[0, 0], squash[0, 3] = 0.0, 1.0 / W  # a row's pixels all land on pixel centre x = 6.5
    out, _ = reference_warp(colour2, ids, depth, np.stack([flat, squash]), (W, H), 8.0, BACKGROUND_NDC_Z)
    np.testing.assert_array_equal(out[:, 6, :3], colour2[:, 0, :3])
    assert (out[:, :6, 3] == 0).all() and (out[:, 7:, 3] == 0).all()


def test_a_magnified_pixel_becomes_a_square_splat():
    colour, ids, depth = client_images()
    ids[:, :] = 0
    ids[4, 3] = 1
    grow = np.diag([1.5, 1.5, 1.0, 1.0])  # 1.5x: splats of ceil(1.5) = 2 pixels
    out, _ = reference_warp(colour, ids, depth, np.stack([np.eye(4), grow]), (W, H), 8.0, BACKGROUND_NDC_Z)
    lone = np.all(out[:, :, :3] == colour[4, 3, :3], axis=2)
    rows, cols = np.nonzero(lone)
    assert len(rows) == 4 and np.ptp(rows) == 1 and np.ptp(cols) == 1


def test_depth_slopes_use_the_flatter_side_and_only_the_same_object():
    depth = np.zeros((3, 5))
    depth[:, :] = np.array([0.0, 0.1, 0.2, 0.9, 0.9])
    ids = np.array([[1, 1, 1, 2, 2]] * 3)
    slopes = depth_slopes(depth, ids)
    per_pixel = 5 / 2.0  # NDC per pixel is 2 / width
    np.testing.assert_allclose(slopes[:, 1, 0], 0.1 * per_pixel)
    # pixel 2 borders object 2: only its left neighbour counts
    np.testing.assert_allclose(slopes[:, 2, 0], 0.1 * per_pixel)
    np.testing.assert_allclose(slopes[:, 3, 0], 0.0)
    np.testing.assert_allclose(slopes[:, :, 1], 0.0)
