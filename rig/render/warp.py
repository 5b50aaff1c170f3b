"""The warp renderer of the seed architecture (Smit et al. 2010; Smit, van Liere, Froehlich 2010).

A client renders the scene at its own, slow pace into colour, per-pixel object ID and depth, with
a field of view a border wider than the display's, and keeps with each frame the object and camera
matrices it drew with. A server runs at every display refresh: it builds one warp matrix per object
from the newest poses (`rig.render.warp_matrices`), re-projects every client pixel with it
(`rig.render.warp_server`), composites the client views with the depth test, and fills the holes.
The tracked sphere follows the predictor at every refresh, so the latency the rig measures does not
depend on how long the client takes; only the image quality does.

Objects and what moves them on the server:

* the sphere (ID 1) is bound to the tracker: its server matrix is the newest predicted position
  (position only: the sphere is rotation-symmetric and its shading is baked in by the client, as
  the direct renderer draws it);
* the load (ID 2) is not: its server pose is extrapolated from its last two client poses (slerp
  and linear); it does not move, so it keeps the matrix computed once at open;
* the background (ID 0) is static, warped just inside the far plane.

Costs: the renderer reports what the GL work took on this machine: wall time until the GPU
finished, without the readback a real display would not need (the client waits for the GPU only
when `RenderSetup.wait_for_gpu` asks it to). `last_warp_seconds` also gives the server's GL timer
query.
"""

from __future__ import annotations

import math
import time
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Iterator

import moderngl
import numpy as np

from predictors import Pose
from rig.errors import ConfigError, RigError
from rig.render import gl
from rig.render.protocol import (
    AppFrameRequest,
    AppFrameResult,
    DisplayFrameRequest,
    DisplayFrameResult,
    RenderSetup,
)
from rig.render.warp_client import BACKGROUND_ID, LOAD_ID, OBJECT_COUNT, SPHERE_ID, ClientScene, ClientTarget, ClientView
from rig.render.warp_matrices import UntrackedMotion, pose_matrix, translation, warp_matrix, widened_projection
from rig.render.warp_server import RECONSTRUCTIONS, WarpServer

BORDER_FRACTION = 0.05
"""The client sees this fraction of the display's width (height) more on each side."""
SECOND_VIEW_DEG = 4.0
"""The second client view turns this far about the vertical axis through the view's centre."""
LOAD_POSE = (np.zeros(3), np.array([1.0, 0.0, 0.0, 0.0]))
"""The load's body pose in the world (position, orientation): fixed, as the direct renderer draws it."""


@dataclass
class _ClientFrame:
    """A finished or in-flight client frame: what it drew and where its images are."""

    t_pose: float
    sphere_position: np.ndarray
    load_pose: Pose
    targets: list[ClientTarget]


class _WarpTimer:
    """Times the server's GL work two ways: wall time until the GPU has finished (what the frame
    costs the system, the measured cost) and a GL timer query (the GPU's own account, None where
    the driver reports nothing; on software GL it misses work done before the rasteriser)."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self._ctx = ctx
        self._query = ctx.query(time=True)
        self.wall_s = 0.0
        self.gpu_s: float | None = None

    @contextmanager
    def measure(self) -> Iterator[None]:
        start = time.perf_counter()
        with self._query:
            yield
        self._ctx.finish()
        self.wall_s = time.perf_counter() - start
        elapsed = self._query.elapsed
        self.gpu_s = elapsed / 1e9 if elapsed > 0 else None


class WarpRenderer:
    """Client-server depth-image warping; see the module docstring.

    views: 1 or 2 client viewpoints (the second, turned by SECOND_VIEW_DEG, sees some of what the
    first one's objects hide; the server warps both, so it costs twice the pixels).
    reconstruction: "point" (Jacobian-sized point splats) or "quad" (parallelogram splats).
    border_fraction: how much wider the client's view is than the display's, per side.
    """

    name = "warp"
    per_display_frame = True

    def __init__(self, views: int = 1, reconstruction: str = "point", border_fraction: float = BORDER_FRACTION) -> None:
        if views not in (1, 2):
            raise ConfigError(f"the warp renderer draws 1 or 2 client views, got {views!r}")
        if reconstruction not in RECONSTRUCTIONS:
            raise ConfigError(f"warp reconstruction must be one of {', '.join(RECONSTRUCTIONS)}, got {reconstruction!r}")
        if not (math.isfinite(border_fraction) and 0.0 <= border_fraction <= 1.0):
            raise ConfigError(f"the client's border must be 0-1 of the display size, got {border_fraction!r}")
        self.views = views
        self.reconstruction = reconstruction
        self.border_fraction = border_fraction
        self._ctx: moderngl.Context | None = None
        self._setup: RenderSetup | None = None
        self._resources: list = []
        self._frames: dict[int, _ClientFrame] = {}
        self._free_targets: list[list[ClientTarget]] = []
        self._reference: tuple[ClientTarget, np.ndarray] | None = None

    # -- protocol ------------------------------------------------------------------------------

    def open(self, setup: RenderSetup) -> None:
        if self._ctx is not None:
            raise RigError("the warp renderer is already open; close() it before opening it again")
        ctx = gl.create_context()
        self._ctx = ctx
        try:
            with ctx:
                gl.check_setup(setup, ctx)
                self._build(setup)
        except BaseException:
            self.close()
            raise
        self._setup = setup

    def _build(self, setup: RenderSetup) -> None:
        ctx = self._ctx
        world_to_clip = np.asarray(setup.world_to_clip, dtype=np.float64)
        self.server_size = (int(setup.width), int(setup.height))
        border = tuple(int(math.ceil(self.border_fraction * s)) for s in self.server_size)
        self.client_size = (self.server_size[0] + 2 * border[0], self.server_size[1] + 2 * border[1])
        widened = widened_projection(world_to_clip, self.server_size, border)
        self._client_views = [ClientView(widened)]
        if self.views == 2:
            self._client_views.append(ClientView(widened @ _turn_about_centre(world_to_clip, SECOND_VIEW_DEG)))
        self._world_to_clip = world_to_clip
        self._load_mesh_to_body = np.linalg.inv(world_to_clip)
        self._scene = ClientScene(ctx, setup.sphere_radius_m, gl.load_triangles(setup.scene_triangles, setup.seed))
        self._resources.append(self._scene)
        self._server = WarpServer(ctx, self.client_size, self.server_size, OBJECT_COUNT, self.reconstruction)
        self._resources.append(self._server)
        self._timer = _WarpTimer(ctx)
        self._shown_frame = -1
        self._load_motion = UntrackedMotion()
        self._static_rows = [self._static_matrices(view) for view in self._client_views]

    @property
    def last_warp_seconds(self) -> tuple[float, float | None]:
        """The latest display frame's warp and fill: (wall seconds until the GPU finished, GL timer
        query seconds or None), without the readback."""
        self._check_open()
        return self._timer.wall_s, self._timer.gpu_s

    def render_app_frame(self, request: AppFrameRequest) -> AppFrameResult:
        """Client: draw the scene with the tracked sphere where it is as the frame starts; keep the
        images on the GPU.

        As in the seeds, the client samples the tracker at the start of its frame rather than
        predicting to the frame's photons: the server moves the sphere to the newest pose anyway,
        and extrapolating across a slow client frame can carry the sphere out of the client's view,
        leaving the server no pixels to warp.
        """
        setup = self._check_open()
        pose = request.predict(request.t_start)
        if request.index in self._frames:
            raise RigError(f"application frame {request.index} was already rendered; indices must be new")
        targets = self._free_targets.pop() if self._free_targets else [self._new_target() for _ in self._client_views]
        load_pose = Pose(request.t_start, *LOAD_POSE)
        start = time.perf_counter()
        with self._ctx:
            for target, view in zip(targets, self._client_views):
                self._scene.draw(target, view, self._load_model(load_pose), pose.position)
                self._scene.prepare_surface(target)
            if setup.wait_for_gpu:
                self._ctx.finish()
        elapsed = time.perf_counter() - start
        self._frames[request.index] = _ClientFrame(float(request.t_start), np.array(pose.position), load_pose, targets)
        return AppFrameResult(elapsed, pose, None)

    def render_display_frame(self, request: DisplayFrameRequest) -> DisplayFrameResult:
        """Server: warp the newest finished client frame (`request.app_frame`) to the newest pose."""
        self._check_open()
        pose = request.predict(request.t_photon)
        if request.app_frame < 0:
            image = np.zeros((self.server_size[1], self.server_size[0], 3), dtype=np.uint8)
            return DisplayFrameResult(image, 0.0, pose)
        frame = self._switch_to(request.app_frame)
        matrices = self._matrices(frame, pose, request.t_photon)
        with self._ctx:
            with self._timer.measure():
                self._server.warp(frame.targets, matrices)
                self._server.fill()
            image = self._server.read_rgb()
        return DisplayFrameResult(image, self._timer.wall_s, pose)

    def close(self) -> None:
        if self._ctx is None:
            return
        with self._ctx:
            targets = [t for frame in self._frames.values() for t in frame.targets]
            targets += [t for free in self._free_targets for t in free]
            if self._reference is not None:
                targets.append(self._reference[0])
            for resource in [*targets, *reversed(self._resources)]:
                resource.release()
        self._resources.clear()
        self._frames = {}
        self._free_targets = []
        self._reference = None
        self._ctx.release()
        self._ctx = None
        self._setup = None

    # -- measurement helpers -------------------------------------------------------------------

    def hole_fraction(self) -> float:
        """Fraction of the latest display frame's pixels that nothing was warped to (level-0 holes)."""
        self._check_open()
        with self._ctx:
            return self._server.hole_fraction()

    def render_reference(self, sphere_position: np.ndarray) -> np.ndarray:
        """The scene drawn directly at the display's projection with the sphere at `sphere_position`:
        what the warp approximates, RGB uint8 (h, w, 3), row 0 at the top, for image-error figures.

        The load is drawn once and kept; each call draws only the sphere over it. The result is the
        one-pass render's, pixel for pixel: the sphere is always in front of the load (`rig.render.gl`).
        """
        self._check_open()
        view = ClientView(self._world_to_clip)
        with self._ctx:
            if self._reference is None:
                target = ClientTarget(self._ctx, self.server_size)
                self._scene.draw(target, view, self._load_model(Pose(0.0, *LOAD_POSE)), None)
                self._reference = (target, target.read()[0])
            target, load_layer = self._reference
            target.framebuffer.use()
            target.framebuffer.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            self._scene.draw_sphere(view, sphere_position)
            sphere = target.read()[0]
        image = np.where(sphere[:, :, 3:4] > 0, sphere, load_layer)[:, :, :3]
        return image[::-1].copy()

    # -- internals -----------------------------------------------------------------------------

    def _check_open(self) -> RenderSetup:
        if self._ctx is None or self._setup is None:
            raise RigError("the warp renderer is not open; call open(setup) before rendering")
        return self._setup

    def _new_target(self) -> ClientTarget:
        with self._ctx:
            return ClientTarget(self._ctx, self.client_size)

    def _switch_to(self, index: int) -> _ClientFrame:
        """The client frame `index`, releasing older ones the first time it is shown."""
        if index not in self._frames:
            raise RigError(f"display frame asked for application frame {index}, which was never rendered")
        if index != self._shown_frame:
            for old in [i for i in self._frames if i < index]:
                self._free_targets.append(self._frames.pop(old).targets)
            self._shown_frame = index
            load = self._frames[index].load_pose
            self._load_motion.record(self._frames[index].t_pose, load.position, load.orientation)
        return self._frames[index]

    def _load_model(self, pose: Pose) -> np.ndarray:
        """The load's object matrix: its NDC-valued vertices into the body, the body to the world."""
        return pose_matrix(pose.position, pose.orientation) @ self._load_mesh_to_body

    def _static_matrices(self, view: ClientView) -> np.ndarray:
        """(objects, 4, 4) warp matrices of a client view for objects where the client drew them:
        S_obj inverse(C_obj) cancels, leaving the cameras and each object's projection."""
        eye = np.eye(4)
        rows = np.empty((OBJECT_COUNT, 4, 4))
        rows[BACKGROUND_ID] = rows[LOAD_ID] = warp_matrix(self._world_to_clip, eye, eye, eye, eye, view.world_to_clip)
        rows[SPHERE_ID] = warp_matrix(
            gl.FRONT_HALF_DEPTH @ self._world_to_clip, eye, eye, eye, eye, gl.FRONT_HALF_DEPTH @ view.world_to_clip
        )
        return rows

    def _matrices(self, frame: _ClientFrame, pose: Pose, t_photon: float) -> list[np.ndarray]:
        """Per client view, the warp matrices to the newest poses: the sphere's from the tracker,
        the load's new only when it moves."""
        eye = np.eye(4)
        server_sphere = translation(pose.position)
        client_sphere = translation(frame.sphere_position)
        load_pose = self._load_motion.pose_at(t_photon) if self._load_motion.moving else None
        result = []
        for view, static in zip(self._client_views, self._static_rows):
            rows = static.copy()
            rows[SPHERE_ID] = warp_matrix(
                gl.FRONT_HALF_DEPTH @ self._world_to_clip,
                eye,
                server_sphere,
                client_sphere,
                eye,
                gl.FRONT_HALF_DEPTH @ view.world_to_clip,
            )
            if load_pose is not None:
                rows[LOAD_ID] = warp_matrix(
                    self._world_to_clip, eye, self._load_model(load_pose), self._load_model(frame.load_pose), eye, view.world_to_clip
                )
            result.append(rows)
        return result


def _turn_about_centre(world_to_clip: np.ndarray, degrees: float) -> np.ndarray:
    """A camera motion: world points turned by `degrees` about the world's vertical (y) axis through
    the point the view centres on (NDC origin)."""
    centre = np.linalg.solve(world_to_clip, np.array([0.0, 0.0, 0.0, 1.0]))
    centre = centre[:3] / centre[3]
    angle = np.radians(degrees)
    turn = np.eye(4)
    turn[[0, 0, 2, 2], [0, 2, 0, 2]] = [np.cos(angle), np.sin(angle), -np.sin(angle), np.cos(angle)]
    return translation(centre) @ turn @ translation(-centre)
