"""The warp renderer on headless GL: it agrees with the numpy reference, reproduces the client image
at the client's pose, moves the sphere's pixels by the tracked motion, and marks and fills holes."""

from __future__ import annotations

import numpy as np
import pytest

from predictors import Pose
from rig.errors import ConfigError, RigError
from rig.render import make_renderer
from rig.render.protocol import AppFrameRequest, DisplayFrameRequest, Renderer, RenderSetup
from rig.render.warp import WarpRenderer
from rig.render.warp_reference import reference_warp
from rig.render.warp_server import BACKGROUND_NDC_Z

WIDTH, HEIGHT = 96, 72
RADIUS = 0.06
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
ORTHOGRAPHIC = np.diag([1 / 0.4, 1 / 0.3, -0.5, 1.0])
PX_PER_M = WIDTH / 0.8


def perspective_view() -> np.ndarray:
    """A camera 1 m in front of the origin looking down -z, 50 degree vertical field of view."""
    f = 1.0 / np.tan(np.radians(25.0))
    near, far = 0.3, 3.0
    projection = np.zeros((4, 4))
    projection[0, 0], projection[1, 1] = f * HEIGHT / WIDTH, f
    projection[2, 2], projection[2, 3] = (far + near) / (near - far), 2 * far * near / (near - far)
    projection[3, 2] = -1.0
    view = np.eye(4)
    view[2, 3] = -1.0
    return projection @ view


def at(position) -> callable:
    return lambda t: Pose(t, np.asarray(position, dtype=np.float64), IDENTITY)


def opened(world_to_clip=ORTHOGRAPHIC, triangles: int = 400, **options) -> WarpRenderer:
    renderer = WarpRenderer(**options)
    renderer.open(RenderSetup(WIDTH, HEIGHT, world_to_clip, RADIUS, scene_triangles=triangles, seed=3))
    return renderer


def client_frame(renderer: WarpRenderer, index: int, position) -> None:
    renderer.render_app_frame(AppFrameRequest(index, 0.0, 0.0, at(position)))


def display(renderer: WarpRenderer, index: int, position, app_frame: int) -> np.ndarray:
    return renderer.render_display_frame(DisplayFrameRequest(index, 0.0, 0.0, at(position), app_frame)).image


@pytest.fixture(scope="module")
def front():
    renderer = opened()
    yield renderer
    renderer.close()


@pytest.fixture(scope="module")
def perspective():
    renderer = opened(perspective_view())
    yield renderer
    renderer.close()


def test_the_warp_renderer_is_a_built_in_per_display_frame_renderer():
    renderer = make_renderer("warp")
    assert isinstance(renderer, WarpRenderer) and isinstance(renderer, Renderer)
    assert renderer.name == "warp" and renderer.per_display_frame is True


@pytest.mark.parametrize("view", ["front", "perspective"])
def test_warping_to_the_clients_own_pose_reproduces_the_client_image(view, request):
    renderer = request.getfixturevalue(view)
    position = [0.05, -0.02, 0.0]
    client_frame(renderer, 0, position)
    image = display(renderer, 0, position, 0)
    np.testing.assert_array_equal(image, renderer.render_reference(np.array(position)))
    assert renderer.hole_fraction() == 0.0


def bright_centroid(image: np.ndarray) -> np.ndarray:
    rows, cols = np.nonzero(image.mean(axis=2) > 100)
    return np.array([cols.mean(), rows.mean()])


def test_a_known_translation_moves_the_spheres_pixels_by_exactly_that_much(front):
    """5 pixels right and 3 up (orthographic, 120 px per metre): the sphere's pixels are the client
    image's, shifted by (5, -3) image pixels, wherever the shifted sphere lands."""
    start = np.array([-0.05, 0.01, 0.0])
    moved = start + np.array([5.0, 3.0, 0.0]) / PX_PER_M
    client_frame(front, 1, start)
    client_image = front.render_reference(start)
    image = display(front, 1, moved, 1)
    shifted = np.zeros_like(client_image)
    shifted[: HEIGHT - 3, 5:] = client_image[3:, : WIDTH - 5]
    sphere = shifted.mean(axis=2) > 100
    assert sphere.sum() > 50
    np.testing.assert_array_equal(image[sphere], shifted[sphere])
    np.testing.assert_allclose(bright_centroid(image) - bright_centroid(client_image), [5.0, -3.0], atol=1e-9)


def reference_of_display_frame(renderer: WarpRenderer, app_frame: int, position) -> tuple[np.ndarray, np.ndarray]:
    """What the numpy reference makes of the client frame's images and matrices, all views composited."""
    frame = renderer._frames[app_frame]
    matrices = renderer._matrices(frame, at(position)(0.0), 0.0)
    colour = np.zeros((HEIGHT, WIDTH, 4), dtype=np.uint8)
    depth = np.ones((HEIGHT, WIDTH))
    with renderer._ctx:
        for target, view_matrices in zip(frame.targets, matrices):
            c, d = reference_warp(*target.read(), view_matrices, (WIDTH, HEIGHT), renderer._server.max_splat, BACKGROUND_NDC_Z)
            nearer = d < depth
            colour[nearer], depth[nearer] = c[nearer], d[nearer]
        warped, _ = renderer._server.read_warped()
    return warped, colour


@pytest.mark.parametrize("views", [1, 2])
def test_the_gl_warp_agrees_with_the_numpy_reference(views):
    """Perspective, sphere 0.35 m nearer the eye: magnified 1.5x, so its splats are 2 pixels."""
    renderer = opened(perspective_view(), views=views)
    try:
        client_frame(renderer, 0, [0.0, 0.0, 0.0])
        moved = [0.06, 0.03, 0.35]
        display(renderer, 0, moved, 0)
        warped, expected = reference_of_display_frame(renderer, 0, moved)
    finally:
        renderer.close()
    equal = np.all(warped == expected, axis=2)
    assert equal.mean() >= 0.99
    assert (expected[:, :, 3] == 0).mean() > 0.001  # the test scene has holes: they must agree too


def test_quad_splats_match_point_splats_under_translation():
    renderers = [opened(reconstruction=mode) for mode in ("point", "quad")]
    try:
        images = []
        for renderer in renderers:
            client_frame(renderer, 0, [0.0, 0.0, 0.0])
            images.append(display(renderer, 0, [0.043, -0.021, 0.0], 0))
    finally:
        for renderer in renderers:
            renderer.close()
    assert np.all(images[0] == images[1], axis=2).mean() >= 0.99


def test_holes_are_marked_and_filled_from_behind_not_from_the_sphere(front):
    start, moved = np.zeros(3), np.array([10.0 / PX_PER_M, 0.0, 0.0])  # 10 pixels right
    client_frame(front, 2, start)
    image = display(front, 2, moved, 2)
    with front._ctx:
        warped, _ = front._server.read_warped()
    holes = front.hole_fraction()
    assert holes == pytest.approx(np.mean(warped[:, :, 3] == 0))
    # the sphere moved by more than its radius: most of where it was is a hole
    assert holes * WIDTH * HEIGHT > 0.5 * np.pi * (RADIUS * PX_PER_M) ** 2
    hole_pixels = warped[::-1][:, :, 3] == 0
    assert image[hole_pixels].max() < 100  # filled with the dim load or black, never the bright sphere
    reference = front.render_reference(moved)
    elsewhere = ~hole_pixels
    assert np.all(image[elsewhere] == reference[elsewhere], axis=1).mean() > 0.99


def test_a_display_frame_shows_the_frame_it_is_given_not_a_newer_one(front):
    client_frame(front, 10, [0.0, 0.0, 0.0])
    client_frame(front, 11, [0.1, 0.05, 0.0])  # drawn, but not finished by this refresh
    image = display(front, 0, [0.0, 0.0, 0.0], 10)
    np.testing.assert_array_equal(image, front.render_reference(np.zeros(3)))
    assert front.hole_fraction() == 0.0
    display(front, 1, [0.0, 0.0, 0.0], 11)
    assert front.hole_fraction() > 0.0


def test_before_any_client_frame_the_display_is_dark_and_unknown_frames_are_refused(front):
    assert display(front, 0, [0.0, 0.0, 0.0], -1).max() == 0
    with pytest.raises(RigError, match="never rendered"):
        display(front, 0, [0.0, 0.0, 0.0], 999)
    client_frame(front, 20, [0.0, 0.0, 0.0])
    with pytest.raises(RigError, match="already rendered"):
        client_frame(front, 20, [0.0, 0.0, 0.0])


@pytest.mark.parametrize("wait_for_gpu", [True, False])
def test_client_and_server_report_what_their_work_took(wait_for_gpu):
    renderer = WarpRenderer()
    renderer.open(RenderSetup(WIDTH, HEIGHT, ORTHOGRAPHIC, RADIUS, wait_for_gpu=wait_for_gpu))
    try:
        app = renderer.render_app_frame(AppFrameRequest(0, 0.0, 0.0, at([0.0, 0.0, 0.0])))
        shown = renderer.render_display_frame(DisplayFrameRequest(0, 0.0, 0.0, at([0.0, 0.0, 0.0]), 0))
        wall, gpu = renderer.last_warp_seconds
    finally:
        renderer.close()
    assert app.image is None
    assert app.cost_s > 0.0 and shown.cost_s == wall > 0.0
    assert gpu is None or gpu > 0.0


def test_the_renderer_must_be_open_once_and_options_are_checked():
    renderer = WarpRenderer()
    with pytest.raises(RigError, match="not open"):
        renderer.render_app_frame(AppFrameRequest(0, 0.0, 0.0, at([0.0, 0.0, 0.0])))
    renderer.open(RenderSetup(WIDTH, HEIGHT, ORTHOGRAPHIC, RADIUS))
    with pytest.raises(RigError, match="already open"):
        renderer.open(RenderSetup(WIDTH, HEIGHT, ORTHOGRAPHIC, RADIUS))
    renderer.close()
    renderer.close()
    with pytest.raises(ConfigError):
        WarpRenderer(views=3)
    with pytest.raises(ConfigError):
        WarpRenderer(reconstruction="mesh")
    with pytest.raises(ConfigError):
        WarpRenderer().open(RenderSetup(0, HEIGHT, ORTHOGRAPHIC, RADIUS))


def test_an_untracked_object_that_moves_is_extrapolated_from_its_last_two_client_poses(monkeypatch):
    """The load moves 4 pixels right per 0.1 s between client frames: 0.1 s after the second one
    the server shows it 4 pixels further, as a direct render with the load there does."""
    import rig.render.warp as warp_module

    step = np.array([4.0 / PX_PER_M, 0.0, 0.0])
    renderer = opened(triangles=3000)
    sphere = [0.3, 0.25, 0.0]  # in a corner, out of the way
    try:
        for index, t in enumerate((0.0, 0.1)):
            monkeypatch.setattr(warp_module, "LOAD_POSE", (index * step, IDENTITY))
            renderer.render_app_frame(AppFrameRequest(index, t, t, at(sphere)))
            renderer.render_display_frame(DisplayFrameRequest(index, t, t, at(sphere), index))
        image = renderer.render_display_frame(DisplayFrameRequest(2, 0.2, 0.2, at(sphere), 1)).image
        monkeypatch.setattr(warp_module, "LOAD_POSE", (2 * step, IDENTITY))
        expected = renderer.render_reference(np.array(sphere))
    finally:
        renderer.close()
    assert np.all(image == expected, axis=2).mean() > 0.995
    assert np.all(image == np.roll(expected, -4, axis=1), axis=2).mean() < 0.9  # the load did move


def test_the_client_samples_the_pose_as_its_frame_starts_not_at_its_photons(front):
    """Predicting across a slow client frame could carry the sphere out of the client's view."""
    asked = []

    def predict(t: float) -> Pose:
        asked.append(t)
        return Pose(t, np.zeros(3), IDENTITY)

    front.render_app_frame(AppFrameRequest(30, t_start=1.0, t_photon=2.5, predict=predict))
    assert asked == [1.0]
