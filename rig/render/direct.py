"""The direct (conventional) renderer: each application frame samples the pose and draws the scene.

The display repeats each application frame until the next one is ready, so the latency this
renderer shows grows with the cost of its scene (`RenderSetup.scene_triangles`).
"""

from __future__ import annotations

import time

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
from rig.render.scene import Scene

MSAA_SAMPLES = 4
"""Samples per pixel: smooth sphere edges give the camera a sub-pixel centroid to find."""
LOAD_TO_CLIP = np.eye(4)
"""The load's triangles are drawn where `gl.load_triangles` made them, in the display's NDC."""


class DirectRenderer:
    """Draws a bright sphere at the predicted position in front of dim load geometry.

    The scene is `rig.render.scene`'s, as the warp renderer's. The sphere is rotation-symmetric, so
    only the pose's position moves it. A frame's cost is the wall time of its GL work on this
    machine, from the first draw call until the image is read back.
    """

    name = "direct"
    per_display_frame = False

    def __init__(self) -> None:
        self._setup: RenderSetup | None = None
        self._objects: gl.GLObjects | None = None

    @property
    def load_triangle_count(self) -> int:
        """How many load triangles each frame draws (0 while closed)."""
        return self._scene.triangle_count if self._objects is not None else 0

    def open(self, setup: RenderSetup) -> None:
        if self._objects is not None:
            raise RigError("the direct renderer is already open; close() it before opening it again")
        self._objects = objects = gl.GLObjects(gl.create_context())
        try:
            with objects.ctx:
                gl.check_setup(setup, objects.ctx)
                self._build(objects, setup)
        except BaseException:
            self.close()
            raise
        self._setup = setup

    def _build(self, objects: gl.GLObjects, setup: RenderSetup) -> None:
        """A multisampled framebuffer to draw into, one to resolve it into for readback, and the scene."""
        ctx, keep = objects.ctx, objects.keep
        size = (setup.width, setup.height)
        samples = min(MSAA_SAMPLES, int(ctx.info["GL_MAX_SAMPLES"]))
        self._draw_fbo = keep(
            ctx.framebuffer(
                color_attachments=[keep(ctx.renderbuffer(size, components=4, samples=samples))],
                depth_attachment=keep(ctx.depth_renderbuffer(size, samples=samples)),
            )
        )
        self._image_fbo = keep(ctx.framebuffer(color_attachments=[keep(ctx.renderbuffer(size, components=4))]))
        triangles = gl.load_triangles(setup.scene_triangles, setup.seed, setup.scene_load)
        self._scene = keep(Scene(ctx, setup.sphere_radius_m, triangles))

    def render_app_frame(self, request: AppFrameRequest) -> AppFrameResult:
        """Draw the sphere at the pose predicted for the frame's photons, then the load behind it,
        and read the image back."""
        if self._objects is None or self._setup is None:
            raise RigError("the direct renderer is not open; call open(setup) before rendering")
        pose = request.predict(request.t_photon)
        start = time.perf_counter()
        with self._objects.ctx:
            self._scene.draw(self._draw_fbo, self._setup.world_to_clip, LOAD_TO_CLIP, pose.position)
            self._objects.ctx.copy_framebuffer(self._image_fbo, self._draw_fbo)
            image = gl.read_rgb(self._image_fbo)
        return AppFrameResult(time.perf_counter() - start, pose, image)

    def render_display_frame(self, request: DisplayFrameRequest) -> DisplayFrameResult:
        raise RigError(
            "the direct renderer draws application frames only (per_display_frame is False): "
            "the display repeats each one; call render_app_frame instead"
        )

    def close(self) -> None:
        if self._objects is not None:
            with self._objects.ctx:
                self._objects.release()
            self._objects.ctx.release()
        self._objects = None
        self._setup = None
