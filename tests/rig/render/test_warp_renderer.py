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
from rig.render.image_error import lab_error_percent
from tests.rig.render.warp_reference import arbitrate_views, reference_warp
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


def opened(world_to_clip=ORTHOGRAPHIC, triangles: int = 400, load: str = "soup", **options) -> WarpRenderer:
    renderer = WarpRenderer(**options)
    renderer.open(RenderSetup(WIDTH, HEIGHT, world_to_clip, RADIUS, scene_triangles=triangles, scene_load=load, seed=3))
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
    """The GL warp before filling, and what the numpy reference makes of the client frame's images
    and matrices, views arbitrated."""
    frame = renderer._frames[app_frame]
    matrices = renderer._matrices(frame, np.asarray(position, dtype=np.float64), None)
    with renderer._ctx:
        views = [
            reference_warp(*target.read(), view_matrices, (WIDTH, HEIGHT), renderer._server.max_splat, BACKGROUND_NDC_Z)
            for target, view_matrices in zip(frame.targets, matrices)
        ]
        warped, _, _ = renderer._server.warped.read()
    colour, _ = views[0] if len(views) == 1 else arbitrate_views(*views)
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


def warped_by_each(reconstructions: tuple[str, ...], moved, **scene) -> dict[str, tuple[np.ndarray, np.ndarray, int]]:
    """Per reconstruction: (display image, reference render, primitives drawn) of one client frame
    warped to `moved`, on the scene `opened` makes of `scene`."""
    result = {}
    for mode in reconstructions:
        renderer = opened(recon=mode, **scene)
        try:
            client_frame(renderer, 0, [0.0, 0.0, 0.0])
            image = display(renderer, 0, moved, 0)
            result[mode] = (image, renderer.render_reference(np.asarray(moved, dtype=np.float64)), renderer.last_primitives)
        finally:
            renderer.close()
    return result


@pytest.mark.parametrize("mode", ["quad", "grid"])
def test_quad_splats_and_the_adaptive_grid_match_point_splats_under_translation(mode):
    warped = warped_by_each(("point", mode), [0.043, -0.021, 0.0])
    assert np.all(warped["point"][0] == warped[mode][0], axis=2).mean() >= 0.99


@pytest.mark.parametrize(("load", "triangles"), [("soup", 400), ("meshes", 200_000)])
def test_the_adaptive_grid_draws_at_least_four_times_fewer_primitives_than_point_splats(load, triangles):
    warped = warped_by_each(("point", "grid"), [0.043, -0.021, 0.0], load=load, triangles=triangles)
    assert warped["point"][2] == (WIDTH + 2 * 5) * (HEIGHT + 2 * 4)  # a point per client pixel (5 % border)
    assert 4 * warped["grid"][2] <= warped["point"][2]
    errors = {mode: lab_error_percent(image, reference) for mode, (image, reference, _) in warped.items()}
    assert errors["grid"] <= errors["point"]


def test_an_unmoved_mesh_reproduces_the_client_image():
    """At the client's own pose the mesh's vertices land on pixel centres, each pixel showing its
    own colour; dropping the triangles between the sphere (its own warp) and the load leaves the
    sphere's rim pixels to triangles on either side."""
    renderer = opened(recon="mesh")
    try:
        client_frame(renderer, 0, [0.05, -0.02, 0.0])
        image = display(renderer, 0, [0.05, -0.02, 0.0], 0)
        reference = renderer.render_reference(np.array([0.05, -0.02, 0.0]))
        holes = renderer.hole_fraction()
    finally:
        renderer.close()
    assert holes * WIDTH * HEIGHT < 2 * np.pi * RADIUS * PX_PER_M
    assert np.all(image == reference, axis=2).mean() > 0.995


def test_the_mesh_warp_stays_close_to_the_reference():
    """The mesh interpolates colours and drops triangles across edges (their holes are filled): a
    little more error than point splats, nowhere near a failed warp's."""
    warped = warped_by_each(("point", "mesh"), [0.043, -0.021, 0.0])
    errors = {mode: lab_error_percent(image, reference) for mode, (image, reference, _) in warped.items()}
    assert errors["mesh"] < errors["point"] + 1.0
    assert warped["mesh"][2] == 2 * (WIDTH + 9) * (HEIGHT + 7)


def test_holes_are_marked_and_filled_from_behind_not_from_the_sphere(front):
    start, moved = np.zeros(3), np.array([10.0 / PX_PER_M, 0.0, 0.0])  # 10 pixels right
    client_frame(front, 2, start)
    image = display(front, 2, moved, 2)
    with front._ctx:
        warped, _, _ = front._server.warped.read()
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
    for bad in ({"views": 3}, {"recon": "voxel"}, {"holes": 3}, {"fill": "inpaint"}, {"border": 2.0}, {"untracked": "guess"}):
        with pytest.raises(ConfigError, match=f"warp option {next(iter(bad))}"):
            WarpRenderer(**bad)
    with pytest.raises(TypeError):
        WarpRenderer(reconstruction="point")
    with pytest.raises(ConfigError):
        WarpRenderer().open(RenderSetup(0, HEIGHT, ORTHOGRAPHIC, RADIUS))


def spun_load_image(untracked: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The load turning 900 degrees a second about the view axis (the image centre, a pixel corner),
    client frames at 0 and 0.1 s (0 and 90 degrees), a display frame at 0.2 s (180 degrees: pixel
    centres land on pixel centres): (that display frame, direct renders at 0.1 s and at 0.2 s)."""
    renderer = opened(triangles=3000, spin=900.0, untracked=untracked)
    sphere = [3.0, 3.0, 0.0]  # out of view
    try:
        for index, t in enumerate((0.0, 0.1)):
            renderer.render_app_frame(AppFrameRequest(index, t, t, at(sphere)))
            renderer.render_display_frame(DisplayFrameRequest(index, t, t, at(sphere), index))
        image = renderer.render_display_frame(DisplayFrameRequest(2, 0.2, 0.2, at(sphere), 1)).image
        return image, renderer.render_reference(np.array(sphere), 0.1), renderer.render_reference(np.array(sphere), 0.2)
    finally:
        renderer.close()


def test_an_untracked_object_that_moves_is_extrapolated_from_its_last_two_client_poses():
    """Extrapolated, the load shows turned 180 degrees, as a direct render at 0.2 s does (the rest:
    the background it uncovers, a static object behind a moving one, left to the fill); held, as
    the client drew it at 0.1 s."""
    image, at_client, at_display = spun_load_image("extrapolate")
    assert np.all(image == at_display, axis=2).mean() > 0.9
    assert np.all(at_client == at_display, axis=2).mean() < 0.7  # the load did move
    held, at_client, _ = spun_load_image("hold")
    np.testing.assert_array_equal(held, at_client)


def test_the_client_samples_the_pose_as_its_frame_starts_not_at_its_photons(front):
    """Predicting across a slow client frame could carry the sphere out of the client's view."""
    asked = []

    def predict(t: float) -> Pose:
        asked.append(t)
        return Pose(t, np.zeros(3), IDENTITY)

    front.render_app_frame(AppFrameRequest(30, t_start=1.0, t_photon=2.5, predict=predict))
    assert asked == [1.0]
