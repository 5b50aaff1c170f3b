"""The warp renderer's server: re-projects client frames to the display with per-object matrices.

Reconstructions (Smit et al. 2010, section 4.1; Schollmeyer et al., section 4.1):

* "point": every client pixel is one vertex (its pixel from gl_VertexID; no vertex buffer), drawn
  as a depth-tested point splat sized by the warp's Jacobian;
* "quad": the same vertex drawn as the warped pixel's parallelogram (a geometry shader);
* "mesh": the client pixels as a triangle mesh, two triangles per 2x2 pixels, colours interpolated,
  triangles between objects that move apart dropped;
* "grid": the adaptive grid's cells (`rig.render.warp_grid`), one quad each.

The primitives drawn per client view are counted in `primitives`.

With two client views, the second only fills what the first left empty: its fragments are
discarded wherever the first view's warp covered the pixel, so a second view never makes a pixel
worse than the first alone would (Mark et al.'s two reference frames, with the first as the trusted
one).

Background pixels (object 0) are warped too, as a static object just inside the far plane: the
clear colour redraws the background, and a pixel nothing was warped to is then a true level-0 hole
(section 4.2.1), never mistaken for background. Holes of higher levels are found and re-rendered by
`rig.render.warp_holes`; what is left is filled by `rig.render.warp_fill`.
"""

from __future__ import annotations

from typing import Sequence

import moderngl
import numpy as np

from rig.errors import ConfigError
from rig.render import gl
from rig.render.warp_client import ClientTarget, IdImage
from rig.render.warp_fill import HoleFill
from rig.render.warp_matrices import SPLAT_ROUNDING
from rig.render.warp_shaders import (
    GRID_FRAGMENT_SHADER,
    ID_SCALE,
    WARP_FRAGMENT_SHADER,
    WARP_QUAD_GEOMETRY_SHADER,
    mesh_geometry_shader,
    warp_vertex_shader,
)

RECONSTRUCTIONS = ("point", "quad", "mesh", "grid")
MAX_SPLAT_PX = 8.0
"""Largest point splat (pixels a side): a pixel magnified more than this leaves holes instead."""
BACKGROUND_NDC_Z = 1.0 - 2.0**-10
"""NDC depth the background is warped to: behind every object, inside the far plane."""


def mesh_indices(size: tuple[int, int]) -> np.ndarray:
    """Vertex indices (uint32) of the pixel mesh of a (w, h) image: two triangles per 2x2 pixels."""
    w, h = size
    corner = (np.arange(h - 1)[:, np.newaxis] * w + np.arange(w - 1)[np.newaxis, :]).ravel()
    quads = np.stack([corner, corner + 1, corner + w, corner + 1, corner + w + 1, corner + w], axis=1)
    return quads.astype(np.uint32).ravel()


def motion_classes(matrices: np.ndarray) -> list[int]:
    """Per object, the index of the first object with the same warp matrix: objects of one class
    move together."""
    rows = [np.asarray(m).tobytes() for m in matrices]
    return [rows.index(row) for row in rows]


class WarpServer:
    """The server's GL objects for one display size: warp, hole fill, readback."""

    def __init__(
        self,
        ctx: moderngl.Context,
        client_size: tuple[int, int],
        server_size: tuple[int, int],
        object_count: int,
        reconstruction: str = "point",
        fill: str = "nearest",
        background: tuple[float, float, float] = (0.0, 0.0, 0.0),
    ) -> None:
        if reconstruction not in RECONSTRUCTIONS:
            raise ConfigError(f"warp reconstruction must be one of {', '.join(RECONSTRUCTIONS)}, got {reconstruction!r}")
        self.ctx = ctx
        self.client_size = client_size
        self.server_size = server_size
        self.reconstruction = reconstruction
        self.background = background
        self.primitives: list[int] = []
        """How many primitives the latest warp drew, per client view."""
        self._objects = objects = gl.GLObjects(ctx)
        keep = objects.keep
        self.max_splat = float(min(MAX_SPLAT_PX, ctx.info["GL_POINT_SIZE_RANGE"][1]))

        geometry = {"quad": WARP_QUAD_GEOMETRY_SHADER, "mesh": mesh_geometry_shader(object_count)}.get(reconstruction)
        fragment = GRID_FRAGMENT_SHADER if reconstruction == "grid" else WARP_FRAGMENT_SHADER
        program = keep(
            ctx.program(vertex_shader=warp_vertex_shader(reconstruction, object_count), geometry_shader=geometry, fragment_shader=fragment)
        )
        self.warp_program = program
        settings = {
            "client_colour": 0, "client_surface": 1, "coverage": 2, "client_size": client_size, "id_scale": ID_SCALE,
            "background_ndc_z": BACKGROUND_NDC_Z, "server_size": tuple(float(v) for v in server_size),
            "max_splat": self.max_splat, "splat_rounding": SPLAT_ROUNDING,
        }  # fmt: skip
        for name, value in settings.items():
            if name in program:
                program[name].value = value
        if reconstruction == "mesh":
            indices = keep(ctx.buffer(mesh_indices(client_size).tobytes()))
            self._warp_vao = keep(ctx.vertex_array(program, [], index_buffer=indices, index_element_size=4))
        elif reconstruction != "grid":
            self._warp_vao = keep(ctx.vertex_array(program, []))

        self.warped = IdImage(objects, server_size)
        self.coverage = objects.texture(server_size, 4)

        self.output = keep(ctx.texture(server_size, 4))
        self.output_fbo = keep(ctx.framebuffer(color_attachments=[self.output]))
        self._fill = keep(HoleFill(ctx, server_size, fill, background))

    def begin(self) -> None:
        """Redraw the background: clear the warped image (alpha 0: nothing warped yet) and its depth."""
        self.warped.framebuffer.use()
        self.warped.framebuffer.clear(*self.background, 0.0, depth=1.0)
        self.primitives = []

    def warp(self, targets: Sequence[ClientTarget], matrices: Sequence[np.ndarray]) -> None:
        """Warp each client view's pixels with its (objects, 4, 4) matrices; views after the first
        only fill what the first left empty."""
        ctx = self.ctx
        self.begin()
        for view, (target, view_matrices) in enumerate(zip(targets, matrices, strict=True)):
            if view == 1:
                ctx.copy_framebuffer(self.coverage, self.warped.framebuffer)
            self.warped.framebuffer.use()
            ctx.enable(moderngl.DEPTH_TEST | moderngl.PROGRAM_POINT_SIZE)
            ctx.depth_func = "<"
            gl.write_matrix(self.warp_program, "warp_matrices", view_matrices)
            if "motion_class" in self.warp_program:
                self.warp_program["motion_class"].value = motion_classes(view_matrices)
            if "arbitrate" in self.warp_program:
                self.warp_program["arbitrate"].value = view > 0
            target.colour.use(0)
            target.surface.use(1)
            self.coverage.use(2)
            self.primitives.append(self._draw(target))

    def _draw(self, target: ClientTarget) -> int:
        """Draw one client view's primitives; how many."""
        pixels = self.client_size[0] * self.client_size[1]
        if self.reconstruction == "grid":
            if target.grid_vao is None:
                target.grid_vao = target.objects.keep(
                    self.ctx.vertex_array(self.warp_program, [(target.grid_buffer, "3i/i", "cell")])
                )
            target.grid_vao.render(moderngl.TRIANGLE_STRIP, vertices=4, instances=target.grid_count)
            return target.grid_count
        if self.reconstruction == "mesh":
            self._warp_vao.render(moderngl.TRIANGLES)
            return 2 * (self.client_size[0] - 1) * (self.client_size[1] - 1)
        self._warp_vao.render(moderngl.POINTS, vertices=pixels)
        return pixels

    def fill(self) -> None:
        """Fill the level-0 holes of the warped image into the output image (alpha 0 marks them)."""
        self._fill.fill(self.warped.colour, self.warped.depth, self.output_fbo)

    def read_rgb(self) -> np.ndarray:
        """The output image, RGB uint8 (h, w, 3), row 0 at the top."""
        return gl.read_rgb(self.output_fbo)

    def hole_fraction(self) -> float:
        """Fraction of output pixels that were level-0 holes (nothing warped to them) before filling."""
        w, h = self.server_size
        alpha = np.frombuffer(self.output.read(), dtype=np.uint8).reshape(h, w, 4)[:, :, 3]
        return float(np.mean(alpha < 128))

    def release(self) -> None:
        self._objects.release()
