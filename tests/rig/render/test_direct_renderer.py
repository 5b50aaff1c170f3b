"""The direct renderer draws the sphere where world_to_clip puts it, over dim load geometry."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from predictors import Pose
from rig.errors import ConfigError, RigError
from rig.render import gl
from rig.render.direct import DirectRenderer
from rig.render.protocol import AppFrameRequest, DisplayFrameRequest, Renderer, RenderSetup

WIDTH, HEIGHT = 160, 120
RADIUS = 0.05
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def orthographic(half_width: float, half_height: float, near: float = 0.1, far: float = 10.0) -> np.ndarray:
    """Camera at the origin looking down world -z, +y up: the OpenGL orthographic matrix."""
    m = np.eye(4)
    m[0, 0] = 1.0 / half_width
    m[1, 1] = 1.0 / half_height
    m[2, 2] = -2.0 / (far - near)
    m[2, 3] = -(far + near) / (far - near)
    return m


SIDE_CAMERA_AT = np.array([3.0, 0.2, -0.1])


def side_camera_axes() -> np.ndarray:
    """Rows: the side camera's right, up and backward directions in world coordinates.

    It looks down world -x, rolled 30 degrees about its view axis.
    """
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    right, up, back = np.array([0.0, 0.0, -1.0]), np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0])
    return np.stack([c * right + s * up, -s * right + c * up, back])


def side_camera() -> np.ndarray:
    """An orthographic camera at SIDE_CAMERA_AT with side_camera_axes()."""
    view = np.eye(4)
    view[:3, :3] = side_camera_axes()
    view[:3, 3] = -view[:3, :3] @ SIDE_CAMERA_AT
    return orthographic(0.4, 0.3) @ view


def expected_pixel(world_to_clip: np.ndarray, position: np.ndarray) -> tuple[float, float]:
    """(column, row) of a world point, pixel centres at integers, row 0 at the top."""
    clip = world_to_clip @ np.append(position, 1.0)
    x, y = clip[:2] / clip[3]
    return (x + 1.0) / 2.0 * WIDTH - 0.5, (1.0 - y) / 2.0 * HEIGHT - 0.5


def centroid(image: np.ndarray, floor: float = 0.0) -> tuple[float, float]:
    """Intensity-weighted (column, row) centroid of what is brighter than `floor`."""
    weight = np.clip(image.astype(np.float64).mean(axis=2) - floor, 0.0, None)
    rows, cols = np.indices(weight.shape)
    return float((weight * cols).sum() / weight.sum()), float((weight * rows).sum() / weight.sum())


def request_at(position, t_photon: float = 0.5, asked: list | None = None) -> AppFrameRequest:
    def predict(t: float) -> Pose:
        if asked is not None:
            asked.append(t)
        return Pose(t, np.asarray(position, dtype=np.float64), IDENTITY)

    return AppFrameRequest(index=0, t_start=0.0, t_photon=t_photon, predict=predict)


def opened(world_to_clip: np.ndarray, **options) -> DirectRenderer:
    renderer = DirectRenderer()
    renderer.open(RenderSetup(WIDTH, HEIGHT, world_to_clip, RADIUS, **options))
    return renderer


@pytest.fixture(scope="module")
def front_view():
    renderer = opened(orthographic(0.4, 0.3))
    yield renderer
    renderer.close()


@pytest.fixture(scope="module")
def side_view():
    renderer = opened(side_camera())
    yield renderer
    renderer.close()


def render(renderer: DirectRenderer, position) -> np.ndarray:
    return renderer.render_app_frame(request_at(position)).image


def test_direct_renderer_satisfies_the_protocol():
    renderer = DirectRenderer()
    assert isinstance(renderer, Renderer)
    assert renderer.name == "direct" and renderer.per_display_frame is False


def test_sphere_at_the_origin_is_at_the_image_centre_on_black(front_view):
    image = render(front_view, [0.0, 0.0, -1.0])
    assert image.shape == (HEIGHT, WIDTH, 3) and image.dtype == np.uint8
    col, row = centroid(image)
    assert col == pytest.approx(WIDTH / 2 - 0.5, abs=0.25)
    assert row == pytest.approx(HEIGHT / 2 - 0.5, abs=0.25)
    assert image.max() >= 250
    rows, cols = np.indices((HEIGHT, WIDTH))
    outside = np.hypot(cols - col, rows - row) > RADIUS * WIDTH / 0.8 + 2
    assert image[outside].max() == 0


def test_row_zero_is_the_top_and_x_is_not_mirrored(front_view):
    col, row = centroid(render(front_view, [0.2, 0.15, -1.0]))
    assert row < HEIGHT / 2 - 10
    assert col > WIDTH / 2 + 10


@settings(max_examples=30, deadline=None, derandomize=True)
@given(
    x=st.floats(-0.3, 0.3),
    y=st.floats(-0.2, 0.2),
    z=st.floats(-9.0, -0.5),
)
def test_sphere_centroid_is_where_world_to_clip_puts_it(front_view, x, y, z):
    position = np.array([x, y, z])
    col, row = centroid(render(front_view, position))
    want_col, want_row = expected_pixel(orthographic(0.4, 0.3), position)
    assert col == pytest.approx(want_col, abs=0.25)
    assert row == pytest.approx(want_row, abs=0.25)


@settings(max_examples=30, deadline=None, derandomize=True)
@given(
    across=st.floats(-0.3, 0.3),
    up=st.floats(-0.2, 0.2),
    distance=st.floats(0.5, 9.0),
)
def test_sphere_follows_a_rotated_and_translated_camera(side_view, across, up, distance):
    position = SIDE_CAMERA_AT + np.array([across, up, -distance]) @ side_camera_axes()
    col, row = centroid(render(side_view, position))
    want_col, want_row = expected_pixel(side_camera(), position)
    assert col == pytest.approx(want_col, abs=0.25)
    assert row == pytest.approx(want_row, abs=0.25)


def test_sphere_on_the_axis_of_a_perspective_camera_is_centred_and_lit():
    near, far, focal = 0.1, 10.0, 2.0
    perspective = np.array(
        [
            [focal * HEIGHT / WIDTH, 0.0, 0.0, 0.0],
            [0.0, focal, 0.0, 0.0],
            [0.0, 0.0, -(far + near) / (far - near), -2.0 * far * near / (far - near)],
            [0.0, 0.0, -1.0, 0.0],
        ]
    )
    renderer = opened(perspective)
    try:
        image = render(renderer, [0.0, 0.0, -1.5])
    finally:
        renderer.close()
    col, row = centroid(image)
    assert col == pytest.approx(WIDTH / 2 - 0.5, abs=0.25)
    assert row == pytest.approx(HEIGHT / 2 - 0.5, abs=0.25)
    assert image[HEIGHT // 2 - 1 : HEIGHT // 2 + 1, WIDTH // 2 - 1 : WIDTH // 2 + 1].min() >= 250


def test_interleaved_renderers_each_draw_into_their_own_context(front_view, side_view):
    position = np.array([0.1, 0.1, -0.2])
    for _ in range(2):
        for renderer, world_to_clip in ((front_view, orthographic(0.4, 0.3)), (side_view, side_camera())):
            col, row = centroid(render(renderer, position))
            want_col, want_row = expected_pixel(world_to_clip, position)
            assert col == pytest.approx(want_col, abs=0.25)
            assert row == pytest.approx(want_row, abs=0.25)


def test_the_frame_reports_what_its_work_took(front_view):
    asked: list[float] = []
    result = front_view.render_app_frame(request_at([0.1, 0.0, -1.0], t_photon=2.25, asked=asked))
    assert result.cost_s > 0.0
    assert asked == [2.25]
    assert result.pose.t == 2.25
    np.testing.assert_array_equal(result.pose.position, [0.1, 0.0, -1.0])


def test_load_geometry_has_exactly_n_triangles_and_depends_only_on_the_seed():
    triangles = gl.load_triangles(1234, seed=7)
    assert triangles.shape == (1234, 3, 3) and triangles.dtype == np.float32
    np.testing.assert_array_equal(triangles, gl.load_triangles(1234, seed=7))
    assert not np.array_equal(triangles, gl.load_triangles(1234, seed=8))
    assert np.abs(triangles[:, :, :2]).max() <= 1.0 + gl.LOAD_TRIANGLE_HALF_SIZE
    depth = triangles[:, :, 2]
    assert (depth > 0.0).all() and (depth < 1.0).all()
    assert (depth == depth[:, :1]).all(), "each triangle is flat in depth"
    assert (np.diff(depth[:, 0]) <= 0.0).all(), "drawn far to near, so no fragment is rejected early"
    assert gl.load_triangles(0, seed=7).shape == (0, 3, 3)


@pytest.mark.parametrize("count", [1, 7, 1000, 12345])
def test_the_meshes_load_is_a_few_tessellated_solids_of_exactly_n_triangles(count):
    """Its triangles share their vertices (a soup's do not), lie in the load's depth range, come far
    to near by their mean depth and depend only on the seed."""
    triangles = gl.load_triangles(count, seed=7, shape="meshes")
    assert triangles.shape == (count, 3, 3) and triangles.dtype == np.float32
    np.testing.assert_array_equal(triangles, gl.load_triangles(count, seed=7, shape="meshes"))
    depth = triangles[:, :, 2]
    assert (depth >= gl.LOAD_DEPTH_RANGE[0]).all() and (depth <= gl.LOAD_DEPTH_RANGE[1]).all()
    assert (np.diff(depth.mean(axis=1)) <= 0.0).all()
    if count >= 1000:
        assert len(np.unique(triangles.reshape(-1, 3), axis=0)) < count
        assert not np.array_equal(triangles, gl.load_triangles(count, seed=8, shape="meshes"))


def test_renderer_builds_exactly_the_requested_load():
    renderer = opened(orthographic(0.4, 0.3), scene_triangles=4321)
    try:
        assert renderer.load_triangle_count == 4321
    finally:
        renderer.close()
    assert renderer.load_triangle_count == 0


@pytest.mark.parametrize("depth", [-1.0, -9.8], ids=["near", "at-the-far-plane"])
def test_load_geometry_never_occludes_the_sphere(front_view, depth):
    position = [0.07, -0.03, depth]
    clean = render(front_view, position)
    loaded_renderer = opened(orthographic(0.4, 0.3), scene_triangles=100_000, seed=3)
    try:
        loaded = render(loaded_renderer, position)
    finally:
        loaded_renderer.close()
    want_col, want_row = expected_pixel(orthographic(0.4, 0.3), np.array(position))
    rows, cols = np.indices((HEIGHT, WIDTH))
    distance = np.hypot(cols - want_col, rows - want_row)
    radius_px = RADIUS * WIDTH / 0.8
    np.testing.assert_array_equal(loaded[distance < radius_px - 1.5], clean[distance < radius_px - 1.5])
    background = loaded[distance > radius_px + 1.5]
    assert background.max() <= round(gl.LOAD_MAX_INTENSITY * 255) + 1
    assert (background > 0).mean() > 0.9
    floor = gl.LOAD_MAX_INTENSITY * 255 + 1
    for got, want in zip(centroid(loaded, floor), centroid(clean, floor)):
        assert got == pytest.approx(want, abs=0.05)


def test_rendered_load_is_deterministic_for_the_seed():
    images = []
    for seed in (5, 5, 6):
        renderer = opened(orthographic(0.4, 0.3), scene_triangles=10_000, seed=seed)
        try:
            images.append(render(renderer, [0.0, 0.0, -1.0]))
        finally:
            renderer.close()
    np.testing.assert_array_equal(images[0], images[1])
    assert not np.array_equal(images[0], images[2])


def test_sphere_mesh_lies_on_the_sphere():
    mesh = gl.sphere_mesh(0.3, stacks=8, slices=12)
    assert mesh.indices.shape == (2 * 8 * 12, 3)
    assert mesh.indices.max() < len(mesh.vertices)
    np.testing.assert_allclose(np.linalg.norm(mesh.vertices, axis=1), 0.3, rtol=1e-6)
    np.testing.assert_allclose(mesh.vertices, 0.3 * mesh.normals, atol=1e-7)


def test_headlight_of_an_orthographic_camera_points_at_the_viewer():
    np.testing.assert_allclose(gl.headlight_direction(orthographic(0.4, 0.3)), [0.0, 0.0, 1.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(gl.headlight_direction(side_camera()), [1.0, 0.0, 0.0, 0.0], atol=1e-12)


def test_headlight_of_a_perspective_camera_is_its_eye():
    view = np.eye(4)
    view[:3, 3] = -np.array([1.0, 2.0, 3.0])
    perspective = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, -1.02, -0.202], [0, 0, -1.0, 0]])
    np.testing.assert_allclose(gl.headlight_direction(perspective @ view), [1.0, 2.0, 3.0, 1.0], atol=1e-12)


@pytest.mark.parametrize(
    "change",
    [
        {"width": 0},
        {"height": 100.5},
        {"world_to_clip": np.eye(3)},
        {"world_to_clip": np.full((4, 4), np.nan)},
        {"sphere_radius_m": -0.1},
        {"scene_triangles": -1},
        {"scene_load": "cubes"},
    ],
    ids=lambda change: next(iter(change)),
)
def test_invalid_setup_is_a_config_error(change):
    values = dict(width=WIDTH, height=HEIGHT, world_to_clip=np.eye(4), sphere_radius_m=RADIUS)
    values.update(change)
    renderer = DirectRenderer()
    with pytest.raises(ConfigError, match=next(iter(change))):
        renderer.open(RenderSetup(**values))
    assert renderer.load_triangle_count == 0


def test_rendering_a_closed_renderer_is_an_error():
    with pytest.raises(RigError, match="open"):
        DirectRenderer().render_app_frame(request_at([0.0, 0.0, -1.0]))


def test_opening_twice_is_an_error(front_view):
    with pytest.raises(RigError, match="already open"):
        front_view.open(RenderSetup(WIDTH, HEIGHT, np.eye(4), RADIUS))


def test_display_frames_are_not_the_direct_renderers(front_view):
    request = DisplayFrameRequest(0, 0.0, 0.01, lambda t: Pose(t, np.zeros(3), IDENTITY), app_frame=-1)
    with pytest.raises(RigError, match="render_app_frame"):
        front_view.render_display_frame(request)


def test_missing_opengl_is_a_rig_error(monkeypatch):
    def no_egl(**_):
        raise RuntimeError("eglGetDisplay failed")

    monkeypatch.setattr(gl.moderngl, "create_standalone_context", no_egl)
    with pytest.raises(RigError, match="EGL.*eglGetDisplay failed"):
        gl.create_context()
