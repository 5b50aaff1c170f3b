"""The warp renderer's server: re-projects client frames to the display with per-object matrices.

Every client pixel is one vertex (its pixel from gl_VertexID; no vertex buffer), moved by its
object's warp matrix and drawn as a depth-tested point splat sized by the warp's Jacobian, or as a
quad splat (the warped pixel's parallelogram, through a geometry shader). Several client views
composite through the same depth buffer. The work is one vertex per client pixel whatever the scene
holds, so its cost depends on pixels only.

Background pixels (object 0) are warped too, as a static object just inside the far plane: the
clear colour redraws the background, and a pixel nothing was warped to is then a true level-0 hole
(Smit et al. 2010, section 4.2.1), never mistaken for background. Holes are filled cheaply in one
full-screen pass: a hole shows what lay behind the object that moved away, so it takes the colour
of the farthest of the first covered pixels found in 8 directions. Only hole pixels search.
"""

from __future__ import annotations

from typing import Sequence

import moderngl
import numpy as np

from rig.errors import ConfigError
from rig.render.gl import read_rgb
from rig.render.warp_client import ClientTarget
from rig.render.warp_matrices import SPLAT_ROUNDING
from rig.render.warp_shaders import (
    FILL_FRAGMENT_SHADER,
    FULLSCREEN_VERTEX_SHADER,
    WARP_FRAGMENT_SHADER,
    WARP_QUAD_GEOMETRY_SHADER,
    warp_vertex_shader,
)

RECONSTRUCTIONS = ("point", "quad")
MAX_SPLAT_PX = 8.0
"""Largest point splat (pixels a side): a pixel magnified more than this leaves holes instead."""
BACKGROUND_NDC_Z = 1.0 - 2.0**-10
"""NDC depth the background is warped to: behind every object, inside the far plane."""
FILL_SEARCH_FRACTION = 1.0 / 16.0
"""A hole searches this fraction of the display's larger side, in pixels, in each direction."""


class WarpServer:
    """The server's GL objects for one display size: warp, hole marking and fill, readback."""

    def __init__(
        self,
        ctx: moderngl.Context,
        client_size: tuple[int, int],
        server_size: tuple[int, int],
        object_count: int,
        reconstruction: str = "point",
        background: tuple[float, float, float] = (0.0, 0.0, 0.0),
    ) -> None:
        if reconstruction not in RECONSTRUCTIONS:
            raise ConfigError(f"warp reconstruction must be one of {', '.join(RECONSTRUCTIONS)}, got {reconstruction!r}")
        self.ctx = ctx
        self.client_size = client_size
        self.server_size = server_size
        self.reconstruction = reconstruction
        self.background = background
        self._resources: list = []
        keep = self._keep
        self.max_splat = float(min(MAX_SPLAT_PX, ctx.info["GL_POINT_SIZE_RANGE"][1]))

        geometry = WARP_QUAD_GEOMETRY_SHADER if reconstruction == "quad" else None
        self.warp_program = keep(
            ctx.program(
                vertex_shader=warp_vertex_shader(object_count), geometry_shader=geometry, fragment_shader=WARP_FRAGMENT_SHADER
            )
        )
        self.warp_program["client_colour"].value = 0
        self.warp_program["client_surface"].value = 1
        self.warp_program["client_size"].value = client_size
        self.warp_program["server_size"].value = tuple(float(v) for v in server_size)
        self.warp_program["max_splat"].value = self.max_splat
        self.warp_program["splat_rounding"].value = SPLAT_ROUNDING
        self.warp_program["background_ndc_z"].value = BACKGROUND_NDC_Z
        self.warp_vao = keep(ctx.vertex_array(self.warp_program, []))

        self.warped = keep(ctx.texture(server_size, 4))
        self.warped_depth = keep(ctx.depth_texture(server_size))
        for texture in (self.warped, self.warped_depth):
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.warped_depth.compare_func = ""
        self.warped_fbo = keep(ctx.framebuffer(color_attachments=[self.warped], depth_attachment=self.warped_depth))

        self.output = keep(ctx.texture(server_size, 4))
        self.output_fbo = keep(ctx.framebuffer(color_attachments=[self.output]))
        self.fill_program = keep(ctx.program(vertex_shader=FULLSCREEN_VERTEX_SHADER, fragment_shader=FILL_FRAGMENT_SHADER))
        self.fill_program["warped"].value = 0
        self.fill_program["warped_depth"].value = 1
        self.fill_program["max_steps"].value = int(np.ceil(FILL_SEARCH_FRACTION * max(server_size)))
        self.fill_program["background"].value = background
        self.fill_vao = keep(ctx.vertex_array(self.fill_program, []))

    def _keep(self, resource):
        self._resources.append(resource)
        return resource

    def warp(self, targets: Sequence[ClientTarget], matrices: Sequence[np.ndarray]) -> None:
        """Redraw the background, then warp each client view's pixels with its (objects, 4, 4) matrices."""
        ctx = self.ctx
        self.warped_fbo.use()
        self.warped_fbo.clear(*self.background, 0.0, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST | moderngl.PROGRAM_POINT_SIZE)
        ctx.depth_func = "<"
        for target, view_matrices in zip(targets, matrices, strict=True):
            # moderngl takes matrices column-major; numpy holds them row-major
            columns = np.asarray(view_matrices, dtype=np.float64).transpose(0, 2, 1)
            self.warp_program["warp_matrices"].write(np.ascontiguousarray(columns, dtype=np.float32).tobytes())
            target.colour.use(0)
            target.surface.use(1)
            self.warp_vao.render(moderngl.POINTS, vertices=self.client_size[0] * self.client_size[1])

    def fill(self) -> None:
        """Fill level-0 holes of the warped image into the output image (alpha 0 marks them)."""
        self.ctx.disable(moderngl.DEPTH_TEST)
        self.output_fbo.use()
        self.warped.use(0)
        self.warped_depth.use(1)
        self.fill_vao.render(moderngl.TRIANGLES, vertices=3)

    def read_rgb(self) -> np.ndarray:
        """The output image, RGB uint8 (h, w, 3), row 0 at the top."""
        return read_rgb(self.output_fbo)

    def hole_fraction(self) -> float:
        """Fraction of output pixels that were level-0 holes (nothing warped to them) before filling."""
        w, h = self.server_size
        alpha = np.frombuffer(self.output.read(), dtype=np.uint8).reshape(h, w, 4)[:, :, 3]
        return float(np.mean(alpha < 128))

    def read_warped(self) -> tuple[np.ndarray, np.ndarray]:
        """Before filling: (colour (h, w, 4) uint8 with alpha 255 where covered, window depth (h, w)),
        OpenGL rows (row 0 at the bottom), as `rig.render.warp_reference.reference_warp` returns."""
        w, h = self.server_size
        colour = np.frombuffer(self.warped.read(), dtype=np.uint8).reshape(h, w, 4).copy()
        depth = np.frombuffer(self.warped_depth.read(), dtype=np.float32).reshape(h, w).copy()
        return colour, depth

    def release(self) -> None:
        for resource in reversed(self._resources):
            resource.release()
        self._resources.clear()
