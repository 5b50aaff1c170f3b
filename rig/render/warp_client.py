"""The warp renderer's client: draws the scene into colour, per-pixel object ID and depth.

The scene is the direct renderer's (`rig.render.gl`): the tracked sphere, lit by a headlight, in
front of dim load triangles, on a black background. Each object has a 16-bit ID; 0 is the
background. Load triangles are stored in the display's NDC, so the load's object matrix is
inverse(world_to_clip): it maps those coordinates into the world, where any client view can see
them. There is no multisampling: a pixel has one depth and one object for the warp to move.

For the adaptive-grid warp each client frame also carries its grid cells (`rig.render.warp_grid`);
for re-rendering holes the scene can draw chosen leaves of the load's kd-tree
(`rig.render.warp_holes`).
"""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from rig.render import gl
from rig.render.warp_grid import grid_cells
from rig.render.warp_shaders import (
    CLIENT_LOAD_FRAGMENT_SHADER,
    CLIENT_LOAD_VERTEX_SHADER,
    CLIENT_SPHERE_FRAGMENT_SHADER,
    FULLSCREEN_VERTEX_SHADER,
    ID_SCALE,
    SURFACE_FRAGMENT_SHADER,
)

BACKGROUND_ID = 0
SPHERE_ID = 1
LOAD_ID = 2
OBJECT_COUNT = 3
OBJECT_FAR_NDC = (1.0, 0.0, 1.0)
"""Per object ID, the far end of its NDC depth range (`grid_cells`): the far plane, and for the
sphere the back of the front half it is squeezed into (`rig.render.gl`)."""


class ClientTarget:
    """One client view's images: RGBA8 colour, R16 object ID (id / ID_SCALE) and depth textures,
    the RGBA32F surface texture the warp reads (see `ClientScene.prepare_surface`), and with
    `grid_motion_px` (the largest image motion its frame is warped over, see `grid_cells`) the
    buffer of its adaptive grid's cells (`grid_count` of them) and the server's vertex array over
    it (`grid_vao`, made by the server)."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int], grid_motion_px: float | None = None) -> None:
        self.size = size
        self.grid_motion_px = grid_motion_px
        self.grid_buffer = ctx.buffer(reserve=size[0] * size[1] * 12) if grid_motion_px is not None else None
        self.grid_count = 0
        self.grid_vao: moderngl.VertexArray | None = None
        self.colour = ctx.texture(size, 4)
        self.object_id = ctx.texture(size, 1, dtype="nu2")
        self.depth = ctx.depth_texture(size)
        self.surface = ctx.texture(size, 4, dtype="f4")
        for texture in (self.colour, self.object_id, self.depth, self.surface):
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.depth.compare_func = ""
        self.framebuffer = ctx.framebuffer(color_attachments=[self.colour, self.object_id], depth_attachment=self.depth)
        self.surface_framebuffer = ctx.framebuffer(color_attachments=[self.surface])

    def read(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(colour (h, w, 4) uint8, object ID (h, w) int, window depth (h, w) float32), OpenGL rows
        (row 0 at the bottom): the inputs of `rig.render.warp_reference.reference_warp`."""
        w, h = self.size
        colour = np.frombuffer(self.colour.read(), dtype=np.uint8).reshape(h, w, 4)
        ids = np.frombuffer(self.object_id.read(), dtype=np.uint16).reshape(h, w).astype(np.int64)
        depth = np.frombuffer(self.depth.read(), dtype=np.float32).reshape(h, w)
        return colour.copy(), ids, depth.copy()

    def read_surface(self) -> np.ndarray:
        """The surface texture (h, w, 4) float32, OpenGL rows."""
        w, h = self.size
        return np.frombuffer(self.surface.read(), dtype=np.float32).reshape(h, w, 4)

    def release(self) -> None:
        extra = [r for r in (self.grid_vao, self.grid_buffer) if r is not None]
        for resource in (*extra, self.surface_framebuffer, self.framebuffer, self.surface, self.colour, self.object_id, self.depth):
            resource.release()


@dataclass(frozen=True)
class ClientView:
    """A client viewpoint: its projection (world to clip, before any per-object depth partition)."""

    world_to_clip: np.ndarray


class ClientScene:
    """The scene's GL objects in one context, drawn from any `ClientView` into a `ClientTarget`."""

    def __init__(
        self, ctx: moderngl.Context, sphere_radius_m: float, triangles: np.ndarray, leaf_order: np.ndarray | None = None
    ) -> None:
        """`leaf_order`: the load's triangles in kd-tree leaf order, for `draw_load_leaves`."""
        self.ctx = ctx
        self._resources: list = []
        mesh = gl.sphere_mesh(sphere_radius_m)
        self._sphere_program = self._keep(gl.sphere_program(ctx, np.eye(4), CLIENT_SPHERE_FRAGMENT_SHADER))
        self._sphere_program["object_id"].value = SPHERE_ID / ID_SCALE
        self._sphere_vao = self._keep(
            ctx.vertex_array(
                self._sphere_program,
                [
                    (self._keep(ctx.buffer(mesh.vertices.tobytes())), "3f", "in_vertex"),
                    (self._keep(ctx.buffer(mesh.normals.tobytes())), "3f", "in_normal"),
                ],
                index_buffer=self._keep(ctx.buffer(mesh.indices.tobytes())),
                index_element_size=4,
            )
        )
        self._load_program = self._keep(gl.load_program(ctx, CLIENT_LOAD_VERTEX_SHADER, CLIENT_LOAD_FRAGMENT_SHADER))
        self._load_program["object_id"].value = LOAD_ID / ID_SCALE
        self._surface_program = self._keep(ctx.program(vertex_shader=FULLSCREEN_VERTEX_SHADER, fragment_shader=SURFACE_FRAGMENT_SHADER))
        self._surface_program["client_id"].value = 0
        self._surface_program["client_depth"].value = 1
        self._surface_program["id_scale"].value = ID_SCALE
        self._surface_vao = self._keep(ctx.vertex_array(self._surface_program, []))
        self._load_vao = None
        self._leaf_vao = None
        self.triangle_count = len(triangles)
        if len(triangles):
            vertices = self._keep(ctx.buffer(triangles.tobytes()))
            self._load_vao = self._keep(ctx.vertex_array(self._load_program, [(vertices, "3f", "in_ndc")]))
            if leaf_order is not None:
                indices = (3 * np.asarray(leaf_order, dtype=np.uint32)[:, np.newaxis] + np.arange(3, dtype=np.uint32)).ravel()
                self._leaf_vao = self._keep(
                    ctx.vertex_array(
                        self._load_program, [(vertices, "3f", "in_ndc")], index_buffer=self._keep(ctx.buffer(indices.tobytes())),
                        index_element_size=4,
                    )
                )

    def _keep(self, resource):
        self._resources.append(resource)
        return resource

    def draw(self, target: ClientTarget, view: ClientView, load_model: np.ndarray, sphere_position: np.ndarray | None) -> None:
        """Clear `target` and draw the scene from `view`: the sphere at `sphere_position` (None: no
        sphere), then the load behind it, whose NDC-valued vertices `load_model` maps to the world."""
        ctx = self.ctx
        target.framebuffer.use()
        target.framebuffer.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        ctx.enable(moderngl.DEPTH_TEST)
        if sphere_position is not None:
            self.draw_sphere(view, sphere_position)
        if self._load_vao is not None:
            gl.write_matrix(self._load_program, "object_to_clip", view.world_to_clip @ load_model)
            self._load_vao.render(moderngl.TRIANGLES)

    def draw_sphere(self, view: ClientView, position: np.ndarray) -> None:
        """Draw the sphere at `position` into the framebuffer in use, depth-tested."""
        gl.write_matrix(self._sphere_program, "world_to_clip", view.world_to_clip)
        self._sphere_program["eye"].value = tuple(gl.headlight_direction(view.world_to_clip))
        self._sphere_program["centre"].value = tuple(np.asarray(position, dtype=np.float64))
        self.ctx.enable(moderngl.DEPTH_TEST)
        self._sphere_vao.render(moderngl.TRIANGLES)

    def draw_load_leaves(self, world_to_clip: np.ndarray, load_model: np.ndarray, leaves: list[tuple[int, int]]) -> None:
        """Draw the load's triangles in the leaf ranges (first, count) of `leaf_order` into the
        framebuffer in use, depth-tested, seen through `world_to_clip`."""
        gl.write_matrix(self._load_program, "object_to_clip", world_to_clip @ load_model)
        self.ctx.enable(moderngl.DEPTH_TEST)
        for first, count in leaves:
            self._leaf_vao.render(moderngl.TRIANGLES, vertices=3 * count, first=3 * first)

    def prepare_surface(self, target: ClientTarget) -> None:
        """Fill `target.surface` from its depth and object IDs: per pixel (NDC depth, depth slopes
        along x and y, object id), computed once per client frame instead of once per warp; and
        the target's grid cells where it has a grid."""
        self.ctx.disable(moderngl.DEPTH_TEST)
        target.surface_framebuffer.use()
        target.object_id.use(0)
        target.depth.use(1)
        self._surface_vao.render(moderngl.TRIANGLES, vertices=3)
        if target.grid_buffer is not None:
            cells = grid_cells(target.read_surface(), target.grid_motion_px, OBJECT_FAR_NDC)
            target.grid_buffer.write(cells.tobytes())
            target.grid_count = len(cells)

    def release(self) -> None:
        for resource in reversed(self._resources):
            resource.release()
        self._resources.clear()
