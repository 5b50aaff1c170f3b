"""The warp renderer of the seed architecture (Smit et al. 2010; Smit, van Liere, Froehlich 2010).

A client renders the scene at its own, slow pace into colour, per-pixel object ID and depth, with
a field of view a border wider than the display's, and keeps with each frame the object matrices it
drew with; with two views, the second is drawn at the poses predicted for the end of the span the
frame will be warped over (Mark et al. 1997). A server runs at every display refresh: it builds one
warp matrix per object from the newest poses (`rig.render.warp_matrices`), re-projects the client
views with them (`rig.render.warp_server`), finds and re-renders holes (`rig.render.warp_holes`),
and fills what is left (`rig.render.warp_fill`). The tracked sphere follows the predictor at every
refresh, so the latency the rig measures does not depend on how long the client takes; only the
image quality does. The options are in `rig.render.warp_options`.

Objects and what moves them on the server:

* the sphere (ID 1) is bound to the tracker: its server matrix is the newest predicted position
  (position only: the sphere is rotation-symmetric and its shading is baked in by the client, as
  the direct renderer draws it);
* the load (ID 2) is not: it turns about the view axis at the `spin` option's rate (0: it stays
  put, as the direct renderer draws it); its server pose is extrapolated from its last two client
  poses (slerp and linear) or held; while it does not move it keeps the matrix computed at open;
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
from typing import Any, Iterator

import moderngl
import numpy as np

from predictors import Pose, quaternion
from rig.errors import RigError
from rig.render import gl
from rig.render.protocol import AppFrameRequest, AppFrameResult, DisplayFrameRequest, DisplayFrameResult, RenderSetup
from rig.render.scene import BACKGROUND_ID, LOAD_ID, OBJECT_COUNT, SPHERE_ID, Scene
from rig.render.warp_client import ClientTarget, surface_pass
from rig.render.warp_holes import HoleFinder, build_leaves, hole_blocks, leaves_hit
from rig.render.warp_matrices import UntrackedMotion, pose_matrix, translation, warp_matrix, widened_projection
from rig.render.warp_options import WarpOptions
from rig.render.warp_server import WarpServer


@dataclass(frozen=True)
class _ViewPoses:
    """The poses a client view drew its objects in: the sphere's position and the load's pose."""

    sphere: np.ndarray
    load: Pose


@dataclass
class _ClientFrame:
    """A finished or in-flight client frame: its views' poses (the first as the frame starts) and images."""

    t_pose: float
    views: list[_ViewPoses]
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
    """Client-server depth-image warping; see the module docstring and `WarpOptions` for the options."""

    name = "warp"
    per_display_frame = True

    def __init__(self, **options: Any) -> None:
        self.options = WarpOptions(**options)
        self._ctx: moderngl.Context | None = None
        self._setup: RenderSetup | None = None
        self._objects: gl.GLObjects | None = None
        self._frames: dict[int, _ClientFrame] = {}
        self._free_targets: list[list[ClientTarget]] = []
        self._reference: dict[float | None, np.ndarray] = {}
        self.last_holes: dict[str, int] = {}
        """The latest display frame's holes by level (pixels) and the leaves and triangles re-rendered."""

    # -- protocol ------------------------------------------------------------------------------

    def open(self, setup: RenderSetup) -> None:
        if self._ctx is not None:
            raise RigError("the warp renderer is already open; close() it before opening it again")
        ctx = gl.create_context()
        self._ctx = ctx
        self._objects = gl.GLObjects(ctx)
        try:
            with ctx:
                gl.check_setup(setup, ctx)
                self._build(setup)
        except BaseException:
            self.close()
            raise
        self._setup = setup

    def _build(self, setup: RenderSetup) -> None:
        ctx, options = self._ctx, self.options
        world_to_clip = np.asarray(setup.world_to_clip, dtype=np.float64)
        self.server_size = (int(setup.width), int(setup.height))
        border = tuple(int(math.ceil(options.border * s)) for s in self.server_size)
        self.client_size = (self.server_size[0] + 2 * border[0], self.server_size[1] + 2 * border[1])
        self._grid_motion_px = float(max(1, *border))  # the border: the largest image motion a client frame is drawn for
        self._client_world_to_clip = widened_projection(world_to_clip, self.server_size, border)
        self._world_to_clip = world_to_clip
        self._load_mesh_to_body = np.linalg.inv(world_to_clip)
        self._spin_centre, self._spin_axis = _view_axis(world_to_clip)
        triangles = gl.load_triangles(setup.scene_triangles, setup.seed, setup.scene_load)
        self._leaves = build_leaves(triangles) if options.holes >= 1 else None
        keep = self._objects.keep
        leaf_order = self._leaves.order if self._leaves else None
        self._scene = keep(Scene(ctx, setup.sphere_radius_m, triangles, leaf_order))
        self._surface = surface_pass(self._objects)
        self._server = keep(
            WarpServer(ctx, self.client_size, self.server_size, OBJECT_COUNT, options.recon, options.fill)
        )
        self._holes = None
        if self._leaves is not None:
            self._holes = keep(HoleFinder(ctx, self.server_size, OBJECT_COUNT))
            r = setup.sphere_radius_m
            leaves = self._leaves
            self._holes.set_boxes(
                np.vstack([leaves.box_min, np.full((1, 3), -r)]),
                np.vstack([leaves.box_max, np.full((1, 3), r)]),
                np.r_[np.full(len(leaves.first), LOAD_ID), SPHERE_ID],
            )
        self._timer = _WarpTimer(ctx)
        self._shown_frame = -1
        self._load_motion = UntrackedMotion()
        self._static_rows = self._static_matrices()

    @property
    def last_warp_seconds(self) -> tuple[float, float | None]:
        """The latest display frame's warp, hole resolution and fill: (wall seconds until the GPU
        finished, GL timer query seconds or None), without the readback."""
        self._check_open()
        return self._timer.wall_s, self._timer.gpu_s

    @property
    def last_primitives(self) -> int:
        """How many primitives the latest display frame's warp drew, all views together."""
        return int(sum(self._server.primitives))

    def render_app_frame(self, request: AppFrameRequest) -> AppFrameResult:
        """Client: draw the scene with the tracked sphere where it is as the frame starts (and, with
        two views, where it is predicted to be when the frame's use ends); keep the images on the GPU.

        As in the seeds, the first view samples the tracker at the start of its frame rather than
        predicting to the frame's photons: the server moves the sphere to the newest pose anyway,
        and extrapolating across a slow client frame can carry the sphere out of the client's view,
        leaving the server no pixels to warp. The second view's horizon is the frame's expected use:
        from its photons until the next frame's, taken to be as far again as from its start.
        """
        setup = self._check_open()
        if request.index in self._frames:
            raise RigError(f"application frame {request.index} was already rendered; indices must be new")
        pose = request.predict(request.t_start)
        times = [request.t_start, 2.0 * request.t_photon - request.t_start][: self.options.views]
        views = [_ViewPoses(np.array(pose.position), self._load_pose(times[0]))]
        if self.options.views == 2:
            views.append(_ViewPoses(np.array(request.predict(times[1]).position), self._load_pose(times[1])))
        targets = self._free_targets.pop() if self._free_targets else [self._new_target() for _ in views]
        start = time.perf_counter()
        with self._ctx:
            for target, poses in zip(targets, views):
                load_to_clip = self._client_world_to_clip @ self._load_model(poses.load)
                self._scene.draw(target.framebuffer, self._client_world_to_clip, load_to_clip, poses.sphere)
                target.prepare_surface(self._surface)
            if setup.wait_for_gpu:
                self._ctx.finish()
        elapsed = time.perf_counter() - start
        self._frames[request.index] = _ClientFrame(float(request.t_start), views, targets)
        return AppFrameResult(elapsed, pose, None)

    def render_display_frame(self, request: DisplayFrameRequest) -> DisplayFrameResult:
        """Server: warp the newest finished client frame (`request.app_frame`) to the newest pose."""
        self._check_open()
        pose = request.predict(request.t_photon)
        if request.app_frame < 0:
            image = np.zeros((self.server_size[1], self.server_size[0], 3), dtype=np.uint8)
            return DisplayFrameResult(image, 0.0, pose)
        frame = self._switch_to(request.app_frame)
        load = self._server_load_pose(frame, request.t_photon)
        with self._ctx:
            with self._timer.measure():
                matrices = self._matrices(frame, pose.position, load)
                self._server.warp(frame.targets, matrices)
                if self._holes is not None:
                    moved = {i for i in range(OBJECT_COUNT) if any(not np.array_equal(m[i], self._static_rows[i]) for m in matrices)}
                    self._resolve_holes(pose.position, load if load is not None else frame.views[0].load, moved)
                self._server.fill()
            image = self._server.read_rgb()
        return DisplayFrameResult(image, self._timer.wall_s, pose)

    def close(self) -> None:
        if self._ctx is None:
            return
        with self._ctx:
            targets = [t for frame in self._frames.values() for t in frame.targets]
            targets += [t for free in self._free_targets for t in free]
            for target in targets:
                target.release()
            self._objects.release()
        self._frames = {}
        self._free_targets = []
        self._reference = {}
        self._ctx.release()
        self._ctx = None
        self._setup = None

    # -- measurement helpers -------------------------------------------------------------------

    def hole_fraction(self) -> float:
        """Fraction of the latest display frame's pixels left as level-0 holes (nothing warped or
        re-rendered there) for the fill."""
        self._check_open()
        with self._ctx:
            return self._server.hole_fraction()

    def render_reference(self, sphere_position: np.ndarray, t: float = 0.0) -> np.ndarray:
        """The scene drawn directly at the display's projection with the sphere at `sphere_position`
        and the load where it is at `t`: what the warp approximates, RGB uint8 (h, w, 3), row 0 at
        the top, for image-error figures.

        The load is drawn once per pose and kept; each call draws only the sphere over it. The
        result is the one-pass render's, pixel for pixel: the sphere is always in front of the load
        (`rig.render.gl`).
        """
        self._check_open()
        view = self._world_to_clip
        key = float(t) if self.options.spin else None
        with self._ctx:
            target = ClientTarget(self._ctx, self.server_size)
            try:
                if key not in self._reference:
                    self._scene.draw(target.framebuffer, view, view @ self._load_model(self._load_pose(t)), None)
                    self._reference = {key: target.read()[0]}
                target.framebuffer.use()
                target.framebuffer.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
                self._scene.draw_sphere(view, sphere_position)
                sphere = target.read()[0]
            finally:
                target.release()
        image = np.where(sphere[:, :, 3:4] > 0, sphere, self._reference[key])[:, :, :3]
        return image[::-1].copy()

    # -- internals -----------------------------------------------------------------------------

    def _check_open(self) -> RenderSetup:
        if self._ctx is None or self._setup is None:
            raise RigError("the warp renderer is not open; call open(setup) before rendering")
        return self._setup

    def _new_target(self) -> ClientTarget:
        grid_motion_px = self._grid_motion_px if self.options.recon == "grid" else None
        with self._ctx:
            return ClientTarget(self._ctx, self.client_size, grid_motion_px)

    def _switch_to(self, index: int) -> _ClientFrame:
        """The client frame `index`, releasing older ones the first time it is shown."""
        if index not in self._frames:
            raise RigError(f"display frame asked for application frame {index}, which was never rendered")
        if index != self._shown_frame:
            for old in [i for i in self._frames if i < index]:
                self._free_targets.append(self._frames.pop(old).targets)
            self._shown_frame = index
            frame = self._frames[index]
            self._load_motion.record(frame.t_pose, frame.views[0].load.position, frame.views[0].load.orientation)
        return self._frames[index]

    def _load_pose(self, t: float) -> Pose:
        """The load's body pose at `t`: turned by `spin` degrees a second about the view axis."""
        turn = quaternion.from_axis_angle(self._spin_axis, np.radians(self.options.spin * t))
        position = self._spin_centre - quaternion.rotate(turn, self._spin_centre)
        return Pose(t, position, turn)

    def _server_load_pose(self, frame: _ClientFrame, t: float) -> Pose | None:
        """The load's server pose at `t`; None while it does not move (its static matrix stands)."""
        if not self._load_motion.moving:
            return None
        return self._load_motion.pose_at(t) if self.options.untracked == "extrapolate" else frame.views[0].load

    def _load_model(self, pose: Pose) -> np.ndarray:
        """The load's object matrix: its NDC-valued vertices into the body, the body to the world."""
        return pose_matrix(pose.position, pose.orientation) @ self._load_mesh_to_body

    def _static_matrices(self) -> np.ndarray:
        """(objects, 4, 4) warp matrices for objects where the client drew them: S_obj inverse(C_obj)
        cancels, leaving the cameras and each object's projection."""
        eye = np.eye(4)
        view = self._client_world_to_clip
        rows = np.empty((OBJECT_COUNT, 4, 4))
        rows[BACKGROUND_ID] = rows[LOAD_ID] = warp_matrix(self._world_to_clip, eye, eye, eye, eye, view)
        rows[SPHERE_ID] = warp_matrix(gl.FRONT_HALF_DEPTH @ self._world_to_clip, eye, eye, eye, eye, gl.FRONT_HALF_DEPTH @ view)
        return rows

    def _matrices(self, frame: _ClientFrame, sphere: np.ndarray, load: Pose | None) -> list[np.ndarray]:
        """Per client view, the warp matrices to the newest poses: the sphere's from the tracker,
        the load's (`load`, None while it does not move) from its untracked motion."""
        eye = np.eye(4)
        view = self._client_world_to_clip
        result = []
        for poses in frame.views:
            rows = self._static_rows.copy()
            rows[SPHERE_ID] = warp_matrix(
                gl.FRONT_HALF_DEPTH @ self._world_to_clip, eye, translation(sphere), translation(poses.sphere), eye,
                gl.FRONT_HALF_DEPTH @ view,
            )  # fmt: skip
            if load is not None:
                rows[LOAD_ID] = warp_matrix(self._world_to_clip, eye, self._load_model(load), self._load_model(poses.load), eye, view)
            result.append(rows)
        return result

    def _resolve_holes(self, sphere: np.ndarray, load: Pose, moved: set[int]) -> None:
        """Find the holes of the latest warp against the proxy map at the server's poses (the
        sphere's position, the load's pose; `moved`: the objects whose warp is not the static one)
        and draw what is missing into the warped image (`rig.render.warp_holes`)."""
        load_model = self._load_model(load)
        object_to_clip = np.stack([
            self._world_to_clip, gl.FRONT_HALF_DEPTH @ self._world_to_clip @ translation(sphere), self._world_to_clip @ load_model,
        ])  # fmt: skip
        server = self._server
        levels, proxy = self._holes.find(object_to_clip, server.warped, self.options.holes, moved)
        hit = leaves_hit(self._leaves, object_to_clip[LOAD_ID], hole_blocks(levels, proxy, LOAD_ID))
        ranges = [(int(self._leaves.first[i]), int(self._leaves.count[i])) for i in hit]
        server.warped.framebuffer.use()
        if ranges:
            self._scene.draw_load_leaves(object_to_clip[LOAD_ID], ranges)
        redraw_sphere = bool(np.any((levels > 0) & (proxy == SPHERE_ID)))
        if redraw_sphere:
            self._scene.draw_sphere(self._world_to_clip, sphere)
        self.last_holes = {
            **{f"level_{level}": int(np.sum(levels == level + 1)) for level in range(3)},
            "leaves": len(ranges), "triangles": sum(count for _, count in ranges), "sphere": int(redraw_sphere),
        }  # fmt: skip


def _view_axis(world_to_clip: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The point the view centres on (NDC origin) and the unit direction of the view axis through it."""
    inverse = np.linalg.inv(world_to_clip)
    ends = [inverse @ np.array([0.0, 0.0, z, 1.0]) for z in (-1.0, 0.0, 1.0)]
    near, centre, far = (end[:3] / end[3] for end in ends)
    axis = far - near
    return centre, axis / np.linalg.norm(axis)
