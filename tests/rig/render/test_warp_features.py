"""The seeds' warp features on headless GL, each against the numpy reference where there is one:
two reference views chosen by prediction, hole levels and their re-rendering, the depth-aware
low-pass fill; and the adaptive grid's cells and the load's kd-tree, in numpy."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from predictors import Pose
from rig.render import gl
from rig.render.fill_shaders import LOWPASS_SEARCH_LEVELS
from rig.render.image_error import lab_error_percent, ssim
from rig.render.protocol import AppFrameRequest, DisplayFrameRequest, RenderSetup
from rig.render.warp import WarpRenderer
from rig.render.warp_grid import GRID_TILE, grid_cells
from rig.render.warp_holes import build_leaves, hole_blocks, leaves_hit
from rig.render.warp_matrices import translation
from tests.rig.render.warp_reference import arbitrate_views, depth_slopes, hole_levels, lowpass_fill, reference_warp
from rig.render.warp_server import BACKGROUND_NDC_Z

WIDTH, HEIGHT = 96, 72
RADIUS = 0.06
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
ORTHOGRAPHIC = np.diag([1 / 0.4, 1 / 0.3, -0.5, 1.0])
PX_PER_M = WIDTH / 0.8
SPEED = np.array([10.0 / PX_PER_M, 0.0, 0.0])
"""The sphere's speed in the moving scene: 10 pixels a second, from the centre."""


def moving(t: float) -> Pose:
    return Pose(t, SPEED * t, IDENTITY)


def warp_once(t_display: float = 0.5, triangles: int = 3000, **options) -> tuple[WarpRenderer, np.ndarray, np.ndarray]:
    """An open renderer whose client frame started at 0 with its photons expected at 0.5 s (a
    second view predicted for 1 s), warped to the sphere's place at `t_display`: (renderer, image,
    reference render). The caller closes the renderer."""
    renderer = WarpRenderer(**options)
    renderer.open(RenderSetup(WIDTH, HEIGHT, ORTHOGRAPHIC, RADIUS, scene_triangles=triangles, seed=3))
    renderer.render_app_frame(AppFrameRequest(0, 0.0, 0.5, moving))
    image = renderer.render_display_frame(DisplayFrameRequest(0, t_display, t_display, moving, 0)).image
    return renderer, image, renderer.render_reference(moving(t_display).position)


def figures(**options) -> dict[str, float]:
    renderer, image, reference = warp_once(**options)
    try:
        return {"holes": renderer.hole_fraction(), "lab": lab_error_percent(image, reference), "ssim": ssim(image, reference),
                "equal": float(np.all(image == reference, axis=2).mean())}  # fmt: skip
    finally:
        renderer.close()


def test_the_second_view_is_drawn_where_the_predictor_says_the_frames_use_ends():
    asked = []

    def predict(t: float) -> Pose:
        asked.append(t)
        return moving(t)

    renderer = WarpRenderer(views=2)
    renderer.open(RenderSetup(WIDTH, HEIGHT, ORTHOGRAPHIC, RADIUS))
    try:
        renderer.render_app_frame(AppFrameRequest(0, t_start=1.0, t_photon=1.25, predict=predict))
    finally:
        renderer.close()
    assert asked == [1.0, 1.5]


def test_two_predicted_views_fill_the_holes_of_one_and_never_do_worse():
    one, two = figures(), figures(views=2)
    assert one["holes"] > 0.005 and two["holes"] < one["holes"] / 10
    assert two["lab"] <= one["lab"] and two["ssim"] >= one["ssim"] and two["equal"] > one["equal"]


def test_the_gl_arbitration_of_two_views_agrees_with_the_numpy_reference():
    renderer, _, _ = warp_once(views=2)
    try:
        frame = renderer._frames[0]
        matrices = renderer._matrices(frame, moving(0.5).position, None)
        with renderer._ctx:
            views = [
                reference_warp(*target.read(), m, (WIDTH, HEIGHT), renderer._server.max_splat, BACKGROUND_NDC_Z)
                for target, m in zip(frame.targets, matrices)
            ]
            warped, _, _ = renderer._server.warped.read()
    finally:
        renderer.close()
    expected, _ = arbitrate_views(*views)
    assert (views[0][0][:, :, 3] == 0).sum() > 30  # the first view alone leaves holes the second fills
    assert np.all(warped == expected, axis=2).mean() >= 0.99


def test_re_rendering_resolves_the_holes_a_moving_sphere_leaves():
    """Where the sphere was, the load it hid is drawn again at the server: fewer holes for the
    fill, and where they were resolved the image is the reference's."""
    plain, resolved = figures(), figures(holes=1)
    assert resolved["holes"] < plain["holes"] and resolved["equal"] > plain["equal"]
    assert resolved["lab"] <= plain["lab"]
    renderer, _, _ = warp_once(holes=1)
    try:
        stats = renderer.last_holes
    finally:
        renderer.close()
    assert stats["level_0"] > 30 and 0 < stats["leaves"] and stats["triangles"] > 0


@pytest.mark.parametrize("max_level", [1, 2])
def test_the_gl_hole_levels_agree_with_the_numpy_reference(max_level):
    """A spinning (untracked) load and a moving sphere give holes of every level to classify."""
    renderer, _, _ = warp_once(t_display=0.6, holes=max_level, spin=40.0)
    try:
        server, finder = renderer._server, renderer._holes
        load = renderer._load_pose(0.6)
        object_to_clip = np.stack([
            ORTHOGRAPHIC,
            gl.FRONT_HALF_DEPTH @ ORTHOGRAPHIC @ translation(moving(0.6).position),
            ORTHOGRAPHIC @ renderer._load_model(load),
        ])  # fmt: skip
        with renderer._ctx:
            levels, proxy = finder.find(object_to_clip, server.warped, max_level, {1, 2})
            w, h = WIDTH, HEIGHT
            colour, ids, depth = server.warped.read()
            front = np.frombuffer(finder.proxy_depth.read(), dtype=np.float32).reshape(h, w)
            back = np.frombuffer(finder.proxy_back_depth.read(), dtype=np.float32).reshape(h, w)
    finally:
        renderer.close()
    expected = hole_levels((colour, ids, depth), (proxy, front, back), max_level, {1, 2})
    np.testing.assert_array_equal(levels, expected)
    assert (levels == 2).sum() > 50
    assert max_level == 1 or (levels == 3).sum() > 0


@pytest.fixture(scope="module")
def lowpass_filled() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The moving scene filled by the low-pass pyramid: (image, warp before filling: colour and
    depth in OpenGL rows)."""
    renderer, image, _ = warp_once(fill="lowpass")
    try:
        with renderer._ctx:
            colour, _, depth = renderer._server.warped.read()
    finally:
        renderer.close()
    return image, colour, depth


def test_the_gl_low_pass_fill_agrees_with_the_numpy_reference(lowpass_filled):
    image, colour, depth = lowpass_filled
    holes = colour[:, :, 3] == 0
    assert holes.sum() > 30
    expected = lowpass_fill(colour, depth, LOWPASS_SEARCH_LEVELS)[::-1]
    np.testing.assert_allclose(image[holes[::-1]] / 255.0, expected[holes[::-1]], atol=1.5 / 255)


def test_the_low_pass_fill_shows_what_lay_behind_not_the_sphere(lowpass_filled):
    image, colour, _ = lowpass_filled
    assert image[(colour[:, :, 3] == 0)[::-1]].max() < 100  # the sphere is at least 150 bright


# -- the adaptive grid's cells ------------------------------------------------------------------

MOTION_PX = 16.0
"""The grid tests' motion bound: a 5 % border at 320 pixels."""


def surface(z: np.ndarray, ids: np.ndarray) -> np.ndarray:
    """A client surface (NDC depth, slopes, id) with the slopes the client's surface pass computes."""
    return np.dstack([z, depth_slopes(z, ids), ids]).astype(np.float32)


def coverage(cells: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    count = np.zeros(shape, dtype=np.int64)
    for x, y, side in cells:
        count[y : y + side, x : x + side] += 1
    return count


def grid_perspective(size: tuple[int, int]) -> np.ndarray:
    """A projection 50 degrees high, near 0.1 m and far 10 m, for a client of `size` = (w, h)."""
    f = 1.0 / np.tan(np.radians(25.0))
    near, far = 0.1, 10.0
    projection = np.zeros((4, 4))
    projection[0, 0], projection[1, 1] = f * size[1] / size[0], f
    projection[2, 2], projection[2, 3] = (far + near) / (near - far), 2 * far * near / (near - far)
    projection[3, 2] = -1.0
    return projection


def ndc_depth_of(projection: np.ndarray, eye_depth: np.ndarray) -> np.ndarray:
    return (projection[2, 2] * -eye_depth + projection[2, 3]) / eye_depth


def pixel_grid(size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """NDC x and y of every pixel centre, (h, w) each, OpenGL rows."""
    w, h = size
    return np.meshgrid((np.arange(w) + 0.5) / w * 2 - 1, (np.arange(h) + 0.5) / h * 2 - 1)


def tessellated_sphere_depth(projection: np.ndarray, size: tuple[int, int], centre_m: float, radius_m: float, step_px: int) -> np.ndarray:
    """NDC depth (h, w) of a sphere seen from outside, `centre_m` ahead of the eye, tessellated into
    flat triangles whose vertices lie on it `step_px` pixels apart: on a flat triangle 1/depth is
    affine in the pixel position, so it is interpolated linearly between the vertices."""
    w, h = size
    vx = np.arange(0, w + step_px, step_px) + 0.0
    vy = np.arange(0, h + step_px, step_px) + 0.0
    gx, gy = np.meshgrid(vx / w * 2 - 1, vy / h * 2 - 1)
    ray = np.stack([gx / projection[0, 0], gy / projection[1, 1], -np.ones_like(gx)], axis=-1)
    a = (ray**2).sum(axis=-1)
    b = 2 * centre_m * -ray[..., 2]
    near_hit = (b - np.sqrt(b**2 - 4 * a * (centre_m**2 - radius_m**2))) / (2 * a)  # the ray's length parameter = eye depth
    inverse_depth = 1.0 / near_hit
    px, py = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    i, j = (py // step_px).astype(int), (px // step_px).astype(int)
    u, v = px / step_px - j, py / step_px - i
    lower = u + v <= 1.0
    c00, c10, c01, c11 = inverse_depth[i, j], inverse_depth[i, j + 1], inverse_depth[i + 1, j], inverse_depth[i + 1, j + 1]
    interpolated = np.where(lower, c00 + u * (c10 - c00) + v * (c01 - c00), c11 + (1 - u) * (c01 - c11) + (1 - v) * (c10 - c11))
    return ndc_depth_of(projection, 1.0 / interpolated)


def quad_depths(cell: np.ndarray, surf: np.ndarray) -> np.ndarray:
    """The depth of the grid's quad at each pixel centre of `cell`, as the grid's vertex shader
    builds it: corner depths from the plane of the cell's corner pixels, two triangles of a strip."""
    x, y, side = (int(v) for v in cell)
    h, w = surf.shape[:2]
    corners = {}
    for cx in (0, 1):
        for cy in (0, 1):
            z, slope_x, slope_y, _ = surf[y + cy * (side - 1), x + cx * (side - 1)].astype(np.float64)
            corners[cx, cy] = z + slope_x * (2 * cx - 1) / w + slope_y * (2 * cy - 1) / h
    result = np.empty((side, side))
    for row in range(side):
        for col in range(side):
            u, v = (col + 0.5) / side, (row + 0.5) / side
            if u + v <= 1.0:
                result[row, col] = corners[0, 0] + u * (corners[1, 0] - corners[0, 0]) + v * (corners[0, 1] - corners[0, 0])
            else:
                result[row, col] = corners[1, 1] + (1 - u) * (corners[0, 1] - corners[1, 1]) + (1 - v) * (corners[1, 0] - corners[1, 1])
    return result


def worst_reprojection_px(cells: np.ndarray, surf: np.ndarray, projection: np.ndarray, motion_px: float) -> float:
    """Ground truth: per cell, move the eye sideways (along x, then y) just far enough that the
    cell's nearest pixel moves `motion_px`, warp every pixel once at its own depth and once at the
    quad's, and return the largest distance between the two, in pixels."""
    h, w = surf.shape[:2]
    inverse = np.linalg.inv(projection)
    focal_px = np.array([projection[0, 0] * w / 2, projection[1, 1] * h / 2])
    nx, ny = pixel_grid((w, h))
    worst = 0.0
    for cell in cells:
        x, y, side = (int(v) for v in cell)
        block = (slice(y, y + side), slice(x, x + side))
        points = {}
        for name, z in (("pixel", surf[block][:, :, 0].astype(np.float64)), ("quad", quad_depths(cell, surf))):
            clip = np.stack([nx[block], ny[block], z, np.ones_like(z)], axis=-1) @ inverse.T
            points[name] = clip[..., :3] / clip[..., 3:]
        nearest = -points["pixel"][..., 2].max()
        for axis in (0, 1):
            moved = {}
            for name, eye in points.items():
                shifted = eye.copy()
                shifted[..., axis] += motion_px * nearest / focal_px[axis]
                clip = np.concatenate([shifted, np.ones(shifted.shape[:-1] + (1,))], axis=-1) @ projection.T
                moved[name] = clip[..., axis] / clip[..., 3] * (w, h)[axis] / 2
            worst = max(worst, float(np.abs(moved["pixel"] - moved["quad"]).max()))
    return worst


def test_a_flat_plane_of_one_object_is_all_largest_cells():
    y, x = np.mgrid[0:64, 0:96]
    cells = grid_cells(surface(0.1 + 0.001 * x + 0.002 * y, np.ones((64, 96))), MOTION_PX)
    assert len(cells) == (64 // GRID_TILE) * (96 // GRID_TILE) and set(cells[:, 2]) == {GRID_TILE}


def test_a_tilted_plane_in_perspective_merges_even_next_to_the_far_plane():
    """A plane at 6 to 9.8 m (far plane 10 m), leaning away to the top right: NDC depth 0.987 to
    0.9996, where float32 rounds the depth and its slopes, and where the depth bound is smallest."""
    size = (96, 64)
    projection = grid_perspective(size)
    nx, ny = pixel_grid(size)
    inverse_depth = 1 / 6.0 - 0.02 * (nx + 1) - 0.0125 * (ny + 1)  # a plane: 1/depth affine in the pixel position
    z = ndc_depth_of(projection, 1.0 / inverse_depth)
    assert 0.98 < z.min() and z.max() > 0.999
    cells = grid_cells(surface(z, np.ones(z.shape)), MOTION_PX)
    assert set(cells[:, 2]) == {GRID_TILE}


def test_no_cell_spans_a_depth_step_or_two_objects():
    z = np.full((40, 40), 0.2)
    z[:, 20:] = 0.5  # a step between columns 19 and 20
    ids = np.ones((40, 40))
    ids[25:, :] = 2  # another object from row 25
    cells = grid_cells(surface(z, ids), MOTION_PX)
    for x, y, side in cells:
        assert not (x < 20 < x + side) and not (y < 25 < y + side)
    assert (coverage(cells, (40, 40)) == 1).all()
    assert len(cells) < 40 * 40 / 8


@pytest.mark.parametrize(("step", "splits"), [(0.1, True), (0.02, False)])
def test_a_depth_step_inside_a_tile_splits_unless_its_parallax_is_sub_pixel(step, splits):
    """One object at 1 m whose right part is `step` (relative) farther: a motion of 16 pixels
    shifts a 10 % step 1.45 pixels against the rest, more than any quad can follow within half a
    pixel (it must split), a 2 % step 0.31 pixels (it merges)."""
    size = (64, 64)
    projection = grid_perspective(size)
    depth = np.ones((64, 64))
    depth[:, 40:] = 1.0 + step
    surf = surface(ndc_depth_of(projection, depth), np.ones((64, 64)))
    cells = grid_cells(surf, MOTION_PX)
    spans = [x < 40 < x + side for x, _, side in cells]
    assert any(spans) is not splits
    assert worst_reprojection_px(cells, surf, projection, MOTION_PX) <= 0.5


@pytest.mark.parametrize("motion_px", [MOTION_PX, 64.0])
def test_a_finely_tessellated_sphere_merges_where_its_parallax_error_is_sub_pixel(motion_px):
    """A sphere of 2 m radius, its near side 1 m away, in flat triangles 4 pixels apart: no cell is
    planar, yet the quads it merges into shift no pixel by more than half a pixel (ground truth:
    every pixel warped at its own depth and at its quad's); at 16 pixels of motion every cell is 16
    pixels or more, at 64 pixels more cells are needed, none below 8."""
    size = (128, 96)
    projection = grid_perspective(size)
    surf = surface(tessellated_sphere_depth(projection, size, 3.0, 2.0, step_px=4), np.ones((96, 128)))
    cells = grid_cells(surf, motion_px)
    assert worst_reprojection_px(cells, surf, projection, motion_px) <= 0.5
    assert cells[:, 2].min() >= 8
    if motion_px == MOTION_PX:
        assert cells[:, 2].min() >= 16
    else:
        assert len(cells) > len(grid_cells(surf, MOTION_PX))


@settings(max_examples=30, deadline=None)
@given(
    shape=st.tuples(st.integers(1, 70), st.integers(1, 70)),
    steps=st.lists(st.tuples(st.integers(0, 69), st.floats(-0.3, 0.3)), max_size=4),
    seed=st.integers(0, 1000),
)
def test_the_cells_tile_any_surface_exactly_once(shape, steps, seed):
    rng = np.random.default_rng(seed)
    h, w = shape
    z = np.full(shape, 0.3) + 0.001 * np.arange(w)
    for column, height in steps:
        z[:, min(column, w - 1) :] += height
    ids = rng.integers(0, 3, size=shape) if seed % 2 else np.ones(shape)
    cells = grid_cells(surface(z, ids), MOTION_PX)
    assert (coverage(cells, shape) == 1).all()
    assert all(len(np.unique(ids[y : y + s, x : x + s])) == 1 for x, y, s in cells)


# -- the load's kd-tree ---------------------------------------------------------------------------


def test_every_triangle_is_in_one_leaf_and_inside_its_box():
    rng = np.random.default_rng(4)
    triangles = rng.uniform(-1.0, 1.0, (5000, 3, 3)).astype(np.float32)
    leaves = build_leaves(triangles, leaf_triangles=300)
    assert sorted(leaves.order.tolist()) == list(range(5000))
    assert leaves.count.max() <= 300 and leaves.count.sum() == 5000
    np.testing.assert_array_equal(leaves.first, np.r_[0, np.cumsum(leaves.count)[:-1]])
    for i in range(len(leaves.first)):
        mine = triangles[leaves.order[leaves.first[i] : leaves.first[i] + leaves.count[i]]].reshape(-1, 3)
        assert (mine >= leaves.box_min[i]).all() and (mine <= leaves.box_max[i]).all()


def test_a_ray_meets_the_nearest_leaves_whose_boxes_it_passes_through():
    """One triangle a leaf: two behind each other on the left (depths 0.9 and 0.5), one on the right."""
    corners = np.array([[0.0, 0.0], [0.1, 0.0], [0.0, 0.1]])
    triangles = np.array([np.column_stack([corners + [x, 0.0], np.full(3, z)]) for x, z in ((-0.5, 0.9), (-0.5, 0.5), (0.5, 0.3))])
    leaves = build_leaves(triangles.astype(np.float32), leaf_triangles=1)
    hit = leaves_hit(leaves, np.eye(4), np.array([[-0.45, 0.05]]), per_ray=1)
    assert [leaves.box_min[i][2] for i in hit] == pytest.approx([0.5])
    assert len(leaves_hit(leaves, np.eye(4), np.array([[0.0, 0.5]]))) == 0


def test_hole_blocks_are_the_blocks_holding_an_objects_holes():
    levels = np.zeros((8, 12), dtype=np.uint8)
    proxy = np.full((8, 12), 2)
    levels[1, 1] = levels[5, 9] = 1
    proxy[5, 9] = 1
    np.testing.assert_allclose(hole_blocks(levels, proxy, 2), [[2.0 / 12 * 2 - 1, 2.0 / 8 * 2 - 1]])
