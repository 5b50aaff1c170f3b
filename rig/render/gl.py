"""OpenGL helpers shared by the rig's renderers: context, GL objects, meshes, load geometry, readback.

Depth is partitioned so that the tracked sphere is always in front of the load geometry: the
sphere's vertex shader (`rig.render.scene`) squeezes clip-space depth into the front half of the
depth range (NDC z in [-1, 0]) and the load triangles live in the back half (NDC z in (0, 1)). The
load therefore costs real rasterisation and depth testing but never occludes the sphere, whatever
`world_to_clip` is.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, TypeVar

import moderngl
import numpy as np

from rig.errors import ConfigError, RigError
from rig.render.protocol import RenderSetup
from rig.sim.config import LOAD_SHAPES

GL_VERSION = 330

LOAD_TRIANGLE_HALF_SIZE = 0.04
"""Half-extent (NDC units) of the box each load triangle's vertices are drawn from."""

LOAD_DEPTH_RANGE = (0.2, 0.95)
"""NDC depth of the load triangles: inside the back half of the range, which the sphere never uses."""

LOAD_MESH_OBJECTS = 6
LOAD_MESH_RADIUS = (0.2, 0.45)
"""Range of the meshes' radii across the screen (NDC units); their depth radius is LOAD_MESH_DEPTH_RADIUS."""
LOAD_MESH_DEPTH_RADIUS = 0.15

LOAD_MAX_INTENSITY = 0.1
"""Brightest a load triangle gets (the farthest are darkest): dim beside the sphere's >= 0.6."""

FRONT_HALF_DEPTH = np.array(
    [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.5, -0.5], [0.0, 0.0, 0.0, 1.0]]
)
"""The sphere vertex shader's depth squeeze, z' = (z - w) / 2, as a clip-space matrix: the sphere's
effective projection is FRONT_HALF_DEPTH @ world_to_clip (the warp renderer unprojects with it)."""


def create_context() -> moderngl.Context:
    """A headless OpenGL 3.3 context through EGL.

    The same EGL path uses a real GPU where its driver provides EGL (NVIDIA, Mesa hardware
    drivers) and Mesa's llvmpipe software rasteriser elsewhere. On a machine with several EGL
    devices, the environment variable GLCONTEXT_DEVICE_INDEX (read by glcontext, moderngl's context
    loader) chooses which one.

    Each renderer owns its context, so several may exist in one thread: wrap GL work on one in
    `with ctx:`, which makes it current and restores the previous one afterwards.
    """
    try:
        return moderngl.create_standalone_context(backend="egl", require=GL_VERSION)
    except Exception as exc:
        raise RigError(
            f"could not create a headless OpenGL {GL_VERSION // 100}.{GL_VERSION % 100 // 10} context "
            f"through EGL ({type(exc).__name__}: {exc}); install an EGL driver (e.g. Mesa's libegl1 "
            "and libgl1-mesa-dri for software rendering) or set GLCONTEXT_DEVICE_INDEX to a working "
            "EGL device"
        ) from exc


T = TypeVar("T")

FULLSCREEN_VERTEX_SHADER = """
#version 330
// One triangle covering the viewport, from gl_VertexID 0, 1, 2.
void main() {
    vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
"""


class GLObjects:
    """The GL objects of one part of a renderer, made in one context and released together, newest first."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self._held: list[Any] = []

    def keep(self, resource: T) -> T:
        """Remember `resource` for release and return it."""
        self._held.append(resource)
        return resource

    def texture(self, size: tuple[int, int], components: int, dtype: str = "f1") -> moderngl.Texture:
        """A texture sampled nearest: its texels are read, never blended."""
        texture = self.keep(self.ctx.texture(size, components, dtype=dtype))
        texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        return texture

    def depth_texture(self, size: tuple[int, int]) -> moderngl.Texture:
        """A depth texture sampled nearest, as depths (no comparison)."""
        texture = self.keep(self.ctx.depth_texture(size))
        texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        texture.compare_func = ""
        return texture

    def program(self, vertex_shader: str, fragment_shader: str, **uniforms: Any) -> moderngl.Program:
        """A shader program with `uniforms` set."""
        program = self.keep(self.ctx.program(vertex_shader=vertex_shader, fragment_shader=fragment_shader))
        for name, value in uniforms.items():
            program[name].value = value
        return program

    def fullscreen(self, fragment_shader: str, **uniforms: Any) -> moderngl.VertexArray:
        """A pass of `fragment_shader` over every pixel of the framebuffer in use, with `uniforms` set:
        `render(moderngl.TRIANGLES, vertices=3)` draws one triangle covering the viewport."""
        return self.keep(self.ctx.vertex_array(self.program(FULLSCREEN_VERTEX_SHADER, fragment_shader, **uniforms), []))

    def release(self) -> None:
        for resource in reversed(self._held):
            resource.release()
        self._held.clear()


def check_setup(setup: RenderSetup, ctx: moderngl.Context) -> None:
    """Raise ConfigError if `setup` asks for something invalid or more than `ctx` can draw."""
    for what, value in (("width", setup.width), ("height", setup.height)):
        if not isinstance(value, (int, np.integer)) or value < 1:
            raise ConfigError(f"render {what} must be a positive whole number of pixels, got {value!r}")
    max_size = int(ctx.info["GL_MAX_RENDERBUFFER_SIZE"])
    if setup.width > max_size or setup.height > max_size:
        raise ConfigError(
            f"render size {setup.width}x{setup.height} exceeds this OpenGL's limit of {max_size} pixels a side"
        )
    m = np.asarray(setup.world_to_clip)
    if m.shape != (4, 4) or not np.issubdtype(m.dtype, np.number) or not np.isfinite(m).all():
        raise ConfigError(f"world_to_clip must be a finite 4x4 matrix, got shape {m.shape}")
    if not (np.isfinite(setup.sphere_radius_m) and setup.sphere_radius_m > 0):
        raise ConfigError(f"sphere_radius_m must be a positive number of metres, got {setup.sphere_radius_m!r}")
    if not isinstance(setup.scene_triangles, (int, np.integer)) or setup.scene_triangles < 0:
        raise ConfigError(
            f"scene_triangles must be a whole number >= 0, got {setup.scene_triangles!r}"
        )
    if setup.scene_load not in LOAD_SHAPES:
        raise ConfigError(f"scene_load must be one of {', '.join(LOAD_SHAPES)}, got {setup.scene_load!r}")


@dataclass(frozen=True)
class Mesh:
    """An indexed triangle mesh: float32 vertices and unit normals (V, 3), uint32 indices (T, 3)."""

    vertices: np.ndarray
    normals: np.ndarray
    indices: np.ndarray


def sphere_mesh(radius: float, stacks: int = 32, slices: int = 64) -> Mesh:
    """A UV sphere of `radius` centred at the origin, with `stacks` latitude bands of `slices` quads.

    Poles are rows of coincident vertices, so every band is `slices` quads (two triangles each,
    degenerate at the poles). The silhouette is a regular polygon, symmetric about the centre.
    """
    if stacks < 2 or slices < 3:
        raise ConfigError(f"a sphere mesh needs stacks >= 2 and slices >= 3, got {stacks} and {slices}")
    polar = np.linspace(0.0, np.pi, stacks + 1)
    azimuth = np.linspace(0.0, 2.0 * np.pi, slices + 1)
    p, a = np.meshgrid(polar, azimuth, indexing="ij")
    normals = np.stack([np.sin(p) * np.cos(a), np.cos(p), np.sin(p) * np.sin(a)], axis=-1).reshape(-1, 3)
    row = slices + 1
    i, j = np.meshgrid(np.arange(stacks), np.arange(slices), indexing="ij")
    corner = (i * row + j).ravel()
    quads = np.stack([corner, corner + row, corner + row + 1, corner + 1], axis=-1)
    indices = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    return Mesh(
        vertices=(radius * normals).astype(np.float32),
        normals=normals.astype(np.float32),
        indices=indices.astype(np.uint32),
    )


def load_triangles(count: int, seed: int, shape: str = "soup") -> np.ndarray:
    """`count` load triangles in NDC, shape (count, 3, 3) float32, deterministic for `seed`, far to
    near; `shape` (LOAD_SHAPES) says what they make.

    Triangles come far to near, so (in the soup) every fragment passes the depth test and is shaded
    and written: the GL cost grows linearly with `count` instead of levelling off as early depth
    rejection would make it. Memory is 36 bytes a triangle (5 million: 180 MB, plus the GL driver's
    copy).
    """
    if count < 0:
        raise ConfigError(f"the load triangle count must be >= 0, got {count}")
    if shape not in LOAD_SHAPES:
        raise ConfigError(f"the load's shape must be one of {', '.join(LOAD_SHAPES)}, got {shape!r}")
    rng = np.random.default_rng(seed)
    return _soup(count, rng) if shape == "soup" else _meshes(count, rng)


def _soup(count: int, rng: np.random.Generator) -> np.ndarray:
    """Small random triangles, far to near: centres uniform over the screen, vertices within
    LOAD_TRIANGLE_HALF_SIZE of their centre, each flat at a depth drawn from LOAD_DEPTH_RANGE."""
    triangles = np.empty((count, 3, 3), dtype=np.float32)
    centres = rng.uniform(-1.0, 1.0, size=(count, 1, 2)).astype(np.float32)
    offsets = rng.uniform(-LOAD_TRIANGLE_HALF_SIZE, LOAD_TRIANGLE_HALF_SIZE, size=(count, 3, 2)).astype(np.float32)
    triangles[:, :, :2] = centres + offsets
    depth = np.sort(rng.uniform(*LOAD_DEPTH_RANGE, size=count).astype(np.float32))[::-1]
    triangles[:, :, 2] = depth[:, np.newaxis]
    return triangles


def _meshes(count: int, rng: np.random.Generator) -> np.ndarray:
    """LOAD_MESH_OBJECTS ellipsoids, randomly turned, placed and sized, each a UV sphere
    (`sphere_mesh`) tessellated into its share of `count`; a share that is not a whole tessellation
    draws its first triangles twice (they cost as much and show nothing new). Far to near by the
    triangles' mean depth."""
    objects = min(LOAD_MESH_OBJECTS, count)
    near, far = LOAD_DEPTH_RANGE
    parts = []
    for share in np.diff(np.linspace(0, count, objects + 1).astype(int)):
        stacks = max(2, int(np.sqrt(share / 4)))
        mesh = sphere_mesh(1.0, stacks, max(3, share // (2 * stacks)))
        turn, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        radius = rng.uniform(*LOAD_MESH_RADIUS)
        scale = np.array([radius, radius, LOAD_MESH_DEPTH_RADIUS])
        centre = np.r_[rng.uniform(-0.7, 0.7, 2), rng.uniform(near + LOAD_MESH_DEPTH_RADIUS, far - LOAD_MESH_DEPTH_RADIUS)]
        vertices = (mesh.vertices @ turn.T) * scale + centre
        parts.append(np.resize(vertices[mesh.indices], (share, 3, 3)))
    if not parts:
        return np.empty((0, 3, 3), dtype=np.float32)
    triangles = np.concatenate(parts).astype(np.float32)
    return triangles[np.argsort(-triangles[:, :, 2].mean(axis=1), kind="stable")]


def headlight_direction(world_to_clip: np.ndarray) -> np.ndarray:
    """The projection centre of `world_to_clip` in homogeneous world coordinates, shape (4,) float64.

    It is the point that clip x, y and w all send to zero: the eye (w = 1) for a perspective
    matrix, a direction (w = 0) towards the viewer for an orthographic one. Lighting from it
    shades the sphere symmetrically about its centre in the image.
    """
    m = np.asarray(world_to_clip, dtype=np.float64)
    _, _, vt = np.linalg.svd(m[[0, 1, 3]])
    eye = vt[-1]
    if abs(eye[3]) > 1e-12 * np.abs(eye[:3]).max():
        return eye / eye[3]
    # Towards the viewer is where NDC depth falls (clip w does not change along this direction).
    toward_viewer = -1.0 if m[2] @ eye > 0 else 1.0
    return toward_viewer * eye / np.linalg.norm(eye[:3])


def write_matrix(program: moderngl.Program, name: str, matrix: np.ndarray) -> None:
    """Set the mat4 uniform `name` of `program` to the 4x4 `matrix` (numpy, row-major), or the mat4
    array uniform to the matrices (n, 4, 4)."""
    # moderngl takes matrices column-major; numpy holds them row-major.
    program[name].write(np.asarray(matrix, dtype=np.float64).swapaxes(-1, -2).astype(np.float32).tobytes())


def read_rgb(framebuffer: moderngl.Framebuffer) -> np.ndarray:
    """The framebuffer's colour as RGB uint8, shape (height, width, 3), row 0 at the top.

    OpenGL returns rows bottom-up; this flips them into display (scan-out) order.
    """
    width, height = framebuffer.size
    data = framebuffer.read(components=3, alignment=1)
    return np.frombuffer(data, dtype=np.uint8).reshape(height, width, 3)[::-1].copy()
