"""The scene the rig's renderers draw: the tracked sphere, lit by a headlight, in front of dim load
triangles, on a black background (the depth partition that keeps the sphere in front is in
`rig.render.gl`).

Each object writes its 16-bit ID (`ID_SCALE`) beside its colour; 0 is the background. The direct
renderer draws into a framebuffer with colour only, where the IDs go nowhere; the warp client keeps
them for the warp to move each object's pixels. Load triangles are stored in the display's NDC, and
`load_to_clip` places them: the identity draws them as they were made, and the warp client's
inverse(world_to_clip), then a view, maps them through the world to any view.
"""

from __future__ import annotations

import moderngl
import numpy as np

from rig.render import gl
from rig.render.warp_shaders import ID_SCALE

BACKGROUND_ID = 0
SPHERE_ID = 1
LOAD_ID = 2
OBJECT_COUNT = 3

SPHERE_AMBIENT = 0.6
SPHERE_DIFFUSE = 0.4

SPHERE_VERTEX_SHADER = """
#version 330
uniform mat4 world_to_clip;
uniform vec3 centre;
in vec3 in_vertex;
in vec3 in_normal;
out vec3 v_world;
out vec3 v_normal;
void main() {
    v_world = centre + in_vertex;
    v_normal = in_normal;
    gl_Position = world_to_clip * vec4(v_world, 1.0);
    // front half of the depth range: NDC z in [-1, 0] (near clipping unchanged; the far plane
    // moves out, which a sphere inside the view never notices)
    gl_Position.z = 0.5 * (gl_Position.z - gl_Position.w);
}
"""

SPHERE_FRAGMENT_SHADER = """
#version 330
uniform vec4 eye;
uniform float ambient;
uniform float diffuse;
uniform float object_id;
in vec3 v_world;
in vec3 v_normal;
layout(location = 0) out vec4 f_colour;
layout(location = 1) out float f_id;
void main() {
    vec3 to_eye = normalize(eye.xyz - eye.w * v_world);
    float lit = ambient + diffuse * max(dot(normalize(v_normal), to_eye), 0.0);
    f_colour = vec4(vec3(lit), 1.0);
    f_id = object_id;
}
"""

LOAD_VERTEX_SHADER = """
#version 330
uniform mat4 object_to_clip;
uniform float max_intensity;
uniform vec2 depth_range;
in vec3 in_ndc;
out float v_intensity;
void main() {
    v_intensity = max_intensity * (depth_range.y - in_ndc.z) / (depth_range.y - depth_range.x);
    gl_Position = object_to_clip * vec4(in_ndc, 1.0);
}
"""

LOAD_FRAGMENT_SHADER = """
#version 330
uniform float object_id;
in float v_intensity;
layout(location = 0) out vec4 f_colour;
layout(location = 1) out float f_id;
void main() {
    f_colour = vec4(vec3(v_intensity), 1.0);
    f_id = object_id;
}
"""


class Scene:
    """The scene's GL objects in one context, drawn through any projection into the framebuffer given."""

    def __init__(
        self, ctx: moderngl.Context, sphere_radius_m: float, triangles: np.ndarray, leaf_order: np.ndarray | None = None
    ) -> None:
        """`triangles`: the load (`gl.load_triangles`); `leaf_order`: its triangles in kd-tree leaf
        order, for `draw_load_leaves`."""
        self.ctx = ctx
        self._objects = gl.GLObjects(ctx)
        keep = self._objects.keep
        mesh = gl.sphere_mesh(sphere_radius_m)
        self._sphere_program = self._objects.program(
            SPHERE_VERTEX_SHADER, SPHERE_FRAGMENT_SHADER, ambient=SPHERE_AMBIENT, diffuse=SPHERE_DIFFUSE,
            object_id=SPHERE_ID / ID_SCALE,
        )  # fmt: skip
        self._sphere_vao = keep(
            ctx.vertex_array(
                self._sphere_program,
                [
                    (keep(ctx.buffer(mesh.vertices.tobytes())), "3f", "in_vertex"),
                    (keep(ctx.buffer(mesh.normals.tobytes())), "3f", "in_normal"),
                ],
                index_buffer=keep(ctx.buffer(mesh.indices.tobytes())),
                index_element_size=4,
            )
        )
        self._load_program = self._objects.program(
            LOAD_VERTEX_SHADER, LOAD_FRAGMENT_SHADER, max_intensity=gl.LOAD_MAX_INTENSITY,
            depth_range=gl.LOAD_DEPTH_RANGE, object_id=LOAD_ID / ID_SCALE,
        )  # fmt: skip
        self._load_vao = None
        self._leaf_vao = None
        self.triangle_count = len(triangles)
        if len(triangles):
            vertices = keep(ctx.buffer(triangles.tobytes()))
            self._load_vao = keep(ctx.vertex_array(self._load_program, [(vertices, "3f", "in_ndc")]))
            if leaf_order is not None:
                first_vertex = 3 * np.asarray(leaf_order, dtype=np.uint32)[:, np.newaxis]
                indices = (first_vertex + np.arange(3, dtype=np.uint32)).ravel()
                self._leaf_vao = keep(
                    ctx.vertex_array(
                        self._load_program, [(vertices, "3f", "in_ndc")],
                        index_buffer=keep(ctx.buffer(indices.tobytes())), index_element_size=4,
                    )
                )

    def draw(
        self, framebuffer: moderngl.Framebuffer, world_to_clip: np.ndarray, load_to_clip: np.ndarray,
        sphere_position: np.ndarray | None,
    ) -> None:  # fmt: skip
        """Clear `framebuffer` and draw the scene into it: the sphere at `sphere_position` (None: no
        sphere) seen through `world_to_clip`, then the load behind it, placed by `load_to_clip`."""
        framebuffer.use()
        framebuffer.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self.ctx.enable(moderngl.DEPTH_TEST)
        if sphere_position is not None:
            self.draw_sphere(world_to_clip, sphere_position)
        if self._load_vao is not None:
            gl.write_matrix(self._load_program, "object_to_clip", load_to_clip)
            self._load_vao.render(moderngl.TRIANGLES)

    def draw_sphere(self, world_to_clip: np.ndarray, position: np.ndarray) -> None:
        """Draw the sphere at `position` into the framebuffer in use, depth-tested, lit from the
        projection centre of `world_to_clip`."""
        gl.write_matrix(self._sphere_program, "world_to_clip", world_to_clip)
        self._sphere_program["eye"].value = tuple(gl.headlight_direction(world_to_clip))
        self._sphere_program["centre"].value = tuple(np.asarray(position, dtype=np.float64))
        self.ctx.enable(moderngl.DEPTH_TEST)
        self._sphere_vao.render(moderngl.TRIANGLES)

    def draw_load_leaves(self, load_to_clip: np.ndarray, leaves: list[tuple[int, int]]) -> None:
        """Draw the load's triangles in the leaf ranges (first, count) of `leaf_order` into the
        framebuffer in use, depth-tested, placed by `load_to_clip`."""
        gl.write_matrix(self._load_program, "object_to_clip", load_to_clip)
        self.ctx.enable(moderngl.DEPTH_TEST)
        for first, count in leaves:
            self._leaf_vao.render(moderngl.TRIANGLES, vertices=3 * count, first=3 * first)

    def release(self) -> None:
        self._objects.release()
