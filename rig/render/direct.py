"""The direct (conventional) renderer: each application frame samples the pose and draws the scene.

The display repeats each application frame until the next one is ready, so the latency this
renderer shows grows with the cost of its scene (`RenderSetup.scene_triangles`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import moderngl
import numpy as np

from rig.errors import RigError
from rig.render import gl
from rig.render.protocol import (
    AppFrameRequest,
    AppFrameResult,
    DisplayFrameRequest,
    DisplayFrameResult,
    RenderSetup,
)

MSAA_SAMPLES = 4
"""Samples per pixel: smooth sphere edges give the camera a sub-pixel centroid to find."""


@dataclass
class _Scene:
    """The GL objects of an open renderer, released together on close."""

    ctx: moderngl.Context
    resources: list = field(default_factory=list)
    draw_fbo: moderngl.Framebuffer | None = None
    image_fbo: moderngl.Framebuffer | None = None
    sphere_program: moderngl.Program | None = None
    sphere_vao: moderngl.VertexArray | None = None
    load_vao: moderngl.VertexArray | None = None
    load_triangle_count: int = 0

    def keep(self, resource):
        """Remember `resource` for release and return it."""
        self.resources.append(resource)
        return resource

    def release(self) -> None:
        with self.ctx:
            for resource in reversed(self.resources):
                resource.release()
        self.resources.clear()
        self.ctx.release()


class DirectRenderer:
    """Draws a bright sphere at the predicted position in front of dim load geometry.

    The sphere is rotation-symmetric, so only the pose's position moves it. A frame's cost is the
    wall time of its GL work on this machine, from the first draw call until the image is read back.
    """

    name = "direct"
    per_display_frame = False

    def __init__(self) -> None:
        self._setup: RenderSetup | None = None
        self._scene: _Scene | None = None

    @property
    def load_triangle_count(self) -> int:
        """How many load triangles each frame draws (0 while closed)."""
        return self._scene.load_triangle_count if self._scene is not None else 0

    def open(self, setup: RenderSetup) -> None:
        if self._scene is not None:
            raise RigError("the direct renderer is already open; close() it before opening it again")
        scene = _Scene(gl.create_context())
        try:
            with scene.ctx:
                gl.check_setup(setup, scene.ctx)
                _build(scene, setup)
        except BaseException:
            scene.release()
            raise
        self._scene = scene
        self._setup = setup

    def render_app_frame(self, request: AppFrameRequest) -> AppFrameResult:
        if self._scene is None or self._setup is None:
            raise RigError("the direct renderer is not open; call open(setup) before rendering")
        pose = request.predict(request.t_photon)
        start = time.perf_counter()
        with self._scene.ctx:
            image = _draw(self._scene, pose.position)
        return AppFrameResult(time.perf_counter() - start, pose, image)

    def render_display_frame(self, request: DisplayFrameRequest) -> DisplayFrameResult:
        raise RigError(
            "the direct renderer draws application frames only (per_display_frame is False): "
            "the display repeats each one; call render_app_frame instead"
        )

    def close(self) -> None:
        if self._scene is not None:
            self._scene.release()
        self._scene = None
        self._setup = None


def _build(scene: _Scene, setup: RenderSetup) -> None:
    ctx = scene.ctx
    size = (setup.width, setup.height)
    samples = min(MSAA_SAMPLES, int(ctx.info["GL_MAX_SAMPLES"]))
    scene.draw_fbo = scene.keep(
        ctx.framebuffer(
            color_attachments=[scene.keep(ctx.renderbuffer(size, components=4, samples=samples))],
            depth_attachment=scene.keep(ctx.depth_renderbuffer(size, samples=samples)),
        )
    )
    scene.image_fbo = scene.keep(
        ctx.framebuffer(color_attachments=[scene.keep(ctx.renderbuffer(size, components=4))])
    )

    mesh = gl.sphere_mesh(setup.sphere_radius_m)
    scene.sphere_program = scene.keep(gl.sphere_program(ctx, setup.world_to_clip))
    scene.sphere_vao = scene.keep(
        ctx.vertex_array(
            scene.sphere_program,
            [
                (scene.keep(ctx.buffer(mesh.vertices.tobytes())), "3f", "in_vertex"),
                (scene.keep(ctx.buffer(mesh.normals.tobytes())), "3f", "in_normal"),
            ],
            index_buffer=scene.keep(ctx.buffer(mesh.indices.tobytes())),
            index_element_size=4,
        )
    )

    if setup.scene_triangles > 0:
        triangles = gl.load_triangles(setup.scene_triangles, setup.seed, setup.scene_load)
        scene.load_vao = scene.keep(
            ctx.vertex_array(
                scene.keep(gl.load_program(ctx)),
                [(scene.keep(ctx.buffer(triangles.tobytes())), "3f", "in_ndc")],
            )
        )
        scene.load_triangle_count = len(triangles)


def _draw(scene: _Scene, position: np.ndarray) -> np.ndarray:
    """Draw the sphere at `position`, then the load behind it, and read the image back."""
    scene.draw_fbo.use()
    scene.draw_fbo.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
    scene.ctx.enable(moderngl.DEPTH_TEST)
    scene.sphere_program["centre"].value = tuple(np.asarray(position, dtype=np.float64))
    scene.sphere_vao.render(moderngl.TRIANGLES)
    if scene.load_vao is not None:
        scene.load_vao.render(moderngl.TRIANGLES)
    scene.ctx.copy_framebuffer(scene.image_fbo, scene.draw_fbo)
    return gl.read_rgb(scene.image_fbo)
