"""The warp renderer's client frames: the scene (`rig.render.scene`, the direct renderer's) drawn
into colour, per-pixel object ID and depth, and the surface the warp reads. There is no
multisampling: a pixel has one depth and one object for the warp to move.

For the adaptive-grid warp each client frame also carries its grid cells (`rig.render.warp_grid`);
for re-rendering holes the scene can draw chosen leaves of the load's kd-tree
(`rig.render.warp_holes`).
"""

from __future__ import annotations

import moderngl
import numpy as np

from rig.render import gl
from rig.render.warp_grid import grid_cells
from rig.render.warp_shaders import ID_SCALE, SURFACE_FRAGMENT_SHADER

OBJECT_FAR_NDC = (1.0, 0.0, 1.0)
"""Per object ID, the far end of its NDC depth range (`grid_cells`): the far plane, and for the
sphere the back of the front half it is squeezed into (`rig.render.gl`)."""


class IdImage:
    """RGBA8 colour, R16 object ID (id / ID_SCALE) and depth textures and their framebuffer, made in `objects`."""

    def __init__(self, objects: gl.GLObjects, size: tuple[int, int]) -> None:
        self.size = size
        self.colour = objects.texture(size, 4)
        self.object_id = objects.texture(size, 1, dtype="nu2")
        self.depth = objects.depth_texture(size)
        self.framebuffer = objects.keep(
            objects.ctx.framebuffer(color_attachments=[self.colour, self.object_id], depth_attachment=self.depth)
        )

    def read(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(colour (h, w, 4) uint8, object ID (h, w) int, window depth (h, w) float32), OpenGL rows
        (row 0 at the bottom): the inputs of the tests' numpy reference warp (`tests/rig/render/warp_reference.py`)."""
        w, h = self.size
        colour = np.frombuffer(self.colour.read(), dtype=np.uint8).reshape(h, w, 4)
        ids = np.frombuffer(self.object_id.read(), dtype=np.uint16).reshape(h, w).astype(np.int64)
        depth = np.frombuffer(self.depth.read(), dtype=np.float32).reshape(h, w)
        return colour.copy(), ids, depth.copy()


class ClientTarget(IdImage):
    """One client view's images (`IdImage`), the RGBA32F surface texture the warp reads (see
    `prepare_surface`), and with `grid_motion_px` (the largest image motion its frame is
    warped over, see `grid_cells`) the buffer of its adaptive grid's cells (`grid_count` of them) and
    the server's vertex array over it (`grid_vao`, made by the server in `objects`)."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int], grid_motion_px: float | None = None) -> None:
        self.objects = gl.GLObjects(ctx)
        super().__init__(self.objects, size)
        self.grid_motion_px = grid_motion_px
        self.grid_buffer = None
        if grid_motion_px is not None:
            self.grid_buffer = self.objects.keep(ctx.buffer(reserve=size[0] * size[1] * 12))
        self.grid_count = 0
        self.grid_vao: moderngl.VertexArray | None = None
        self.surface = self.objects.texture(size, 4, dtype="f4")
        self.surface_framebuffer = self.objects.keep(ctx.framebuffer(color_attachments=[self.surface]))

    def prepare_surface(self, surface_pass: moderngl.VertexArray) -> None:
        """Fill `surface` from the depth and object IDs by the pass `surface_pass()` makes: per pixel
        (NDC depth, depth slopes along x and y, object id), computed once per client frame instead of
        once per warp; and the grid cells where the target has a grid."""
        self.objects.ctx.disable(moderngl.DEPTH_TEST)
        self.surface_framebuffer.use()
        self.object_id.use(0)
        self.depth.use(1)
        surface_pass.render(moderngl.TRIANGLES, vertices=3)
        if self.grid_buffer is not None:
            cells = grid_cells(self.read_surface(), self.grid_motion_px, OBJECT_FAR_NDC)
            self.grid_buffer.write(cells.tobytes())
            self.grid_count = len(cells)

    def read_surface(self) -> np.ndarray:
        """The surface texture (h, w, 4) float32, OpenGL rows."""
        w, h = self.size
        return np.frombuffer(self.surface.read(), dtype=np.float32).reshape(h, w, 4)

    def release(self) -> None:
        self.objects.release()


def surface_pass(objects: gl.GLObjects) -> moderngl.VertexArray:
    """The pass that fills a client target's surface (`ClientTarget.prepare_surface`), made in `objects`."""
    return objects.fullscreen(SURFACE_FRAGMENT_SHADER, client_id=0, client_depth=1, id_scale=ID_SCALE)
