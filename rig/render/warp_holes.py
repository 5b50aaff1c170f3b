"""Finding holes of levels 0-2 and resolving them by re-rendering what is missing (Smit et al. 2010,
section 4.2).

Every object is approximated by bounding boxes: the load by the leaves of a kd-tree over its
triangles (LEAF_TRIANGLES each, median splits along the longest axis, built once at open), the
sphere by one box. At every refresh the server draws the boxes at the objects' newest poses into a
proxy map (nearest box front: object ID and depth; nearest box back: depth) and compares it with
the warp (`rig.render.fill_shaders.HOLE_FRAGMENT_SHADER`): a pixel nothing was warped to where a
box says an object is (level 0), another object warped behind a box's front (level 1), or the
box's own object warped behind the back of the nearest box (level 2). Holes where no box is are
background and need nothing but the background.

Holes are resolved as the seeds do: the hole map is read back and reduced to blocks of HOLE_BLOCK
x HOLE_BLOCK pixels (the seed reduces it on the GPU before reading it); for each block holding a
load hole, the leaves whose boxes a ray through the block's centre
meets (here: whose projected bounds contain the centre) are taken nearest first, at most
LEAVES_PER_RAY of them, and their triangles are drawn into the warped image, depth-tested, at the
server's pose; a sphere hole redraws the sphere. What stays a level-0 hole is filled afterwards.
"""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from rig.render import gl
from rig.render.fill_shaders import HOLE_FRAGMENT_SHADER, PROXY_FRAGMENT_SHADER, proxy_vertex_shader
from rig.render.warp_client import IdImage
from rig.render.warp_shaders import ID_SCALE

LEAF_TRIANGLES = 1024
HOLE_BLOCK = 4
LEAVES_PER_RAY = 3
HOLE_LEVELS = (0, 1, 2)


@dataclass(frozen=True)
class LoadLeaves:
    """A kd-tree's leaves over triangles: `order` lists the triangles leaf by leaf (far to near
    within a leaf, as given), leaf i holding order[first[i] : first[i] + count[i]], inside the box
    box_min[i] to box_max[i] (object coordinates)."""

    order: np.ndarray
    first: np.ndarray
    count: np.ndarray
    box_min: np.ndarray
    box_max: np.ndarray


def build_leaves(triangles: np.ndarray, leaf_triangles: int = LEAF_TRIANGLES) -> LoadLeaves:
    """The kd-tree leaves of `triangles` (N, 3, 3): median splits of the centroids along the
    longest axis until a node holds at most `leaf_triangles`."""
    centroids = triangles.mean(axis=1)
    order = np.arange(len(triangles))
    ranges: list[tuple[int, int]] = []
    pending = [(0, len(triangles))]
    while pending:
        start, end = pending.pop()
        if end - start <= leaf_triangles:
            if end > start:
                ranges.append((start, end))
            continue
        points = centroids[order[start:end]]
        axis = int(np.argmax(points.max(axis=0) - points.min(axis=0)))
        half = (end - start) // 2
        split = np.argpartition(points[:, axis], half, kind="introselect")
        left, right = np.sort(split[:half]), np.sort(split[half:])
        order[start:end] = np.concatenate([order[start:end][left], order[start:end][right]])
        pending += [(start + half, end), (start, start + half)]
    ranges.sort()
    first = np.array([r[0] for r in ranges], dtype=np.int64)
    count = np.array([r[1] - r[0] for r in ranges], dtype=np.int64)
    vertices = triangles[order].reshape(len(order), 9)
    lows = np.minimum.reduceat(vertices.reshape(-1, 3, 3).min(axis=1), first)
    highs = np.maximum.reduceat(vertices.reshape(-1, 3, 3).max(axis=1), first)
    return LoadLeaves(order, first, count, lows, highs)


def _box_corners(box_min: np.ndarray, box_max: np.ndarray) -> np.ndarray:
    """(L, 8, 4) homogeneous corners of boxes (L, 3)."""
    bits = np.array([[(c >> k) & 1 for k in range(3)] for c in range(8)], dtype=np.float64)
    corners = box_min[:, np.newaxis, :] + bits[np.newaxis] * (box_max - box_min)[:, np.newaxis, :]
    return np.concatenate([corners, np.ones((*corners.shape[:2], 1))], axis=2)


def leaves_hit(leaves: LoadLeaves, object_to_clip: np.ndarray, centres_ndc: np.ndarray, per_ray: int = LEAVES_PER_RAY) -> np.ndarray:
    """Indices of the leaves whose projected bounds contain any of `centres_ndc` (B, 2), the nearest
    `per_ray` per centre, each once."""
    if not len(centres_ndc) or not len(leaves.first):
        return np.zeros(0, dtype=np.int64)
    clip = _box_corners(leaves.box_min, leaves.box_max) @ np.asarray(object_to_clip, dtype=np.float64).T
    w = np.maximum(clip[:, :, 3:4], 1e-12)
    ndc = clip[:, :, :3] / w
    low, high, near = ndc[:, :, :2].min(axis=1), ndc[:, :, :2].max(axis=1), ndc[:, :, 2].min(axis=1)
    inside = np.all((centres_ndc[:, np.newaxis, :] >= low) & (centres_ndc[:, np.newaxis, :] <= high), axis=2)
    depth = np.where(inside, near[np.newaxis, :], np.inf)
    k = min(per_ray, depth.shape[1])
    nearest = np.argpartition(depth, k - 1, axis=1)[:, :k]
    hit = np.take_along_axis(depth, nearest, axis=1) < np.inf
    return np.unique(nearest[hit])


def hole_blocks(levels: np.ndarray, proxy: np.ndarray, object_id: int, block: int = HOLE_BLOCK) -> np.ndarray:
    """NDC centres (B, 2) of the block x block blocks of a hole map (h, w), OpenGL rows, that hold a
    hole of `object_id`'s proxy."""
    h, w = levels.shape
    ph, pw = -(-h // block) * block, -(-w // block) * block
    mine = np.zeros((ph, pw), dtype=bool)
    mine[:h, :w] = (levels > 0) & (proxy == object_id)
    rows, cols = np.nonzero(mine.reshape(ph // block, block, pw // block, block).any(axis=(1, 3)))
    x = (np.minimum((cols + 0.5) * block, w) / w) * 2.0 - 1.0
    y = (np.minimum((rows + 0.5) * block, h) / h) * 2.0 - 1.0
    return np.column_stack([x, y])


class HoleFinder:
    """The proxy map and the hole map of one server size, in one context (see the module docstring)."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int], object_count: int) -> None:
        self.ctx = ctx
        self.size = size
        self._objects = objects = gl.GLObjects(ctx)
        keep = objects.keep
        self.proxy_id = objects.texture(size, 1, dtype="nu2")
        self.proxy_depth = objects.depth_texture(size)
        self.proxy_back_depth = objects.depth_texture(size)
        self.holes = objects.texture(size, 4)
        self._front_fbo = keep(ctx.framebuffer(color_attachments=[self.proxy_id], depth_attachment=self.proxy_depth))
        self._back_fbo = keep(ctx.framebuffer(depth_attachment=self.proxy_back_depth))
        self._hole_fbo = keep(ctx.framebuffer(color_attachments=[self.holes]))
        self._proxy_program = objects.program(
            proxy_vertex_shader(object_count), PROXY_FRAGMENT_SHADER, id_scale=ID_SCALE
        )
        self._boxes = keep(ctx.buffer(reserve=28))
        self._box_count = 0
        self._proxy_vao: moderngl.VertexArray | None = None
        units = ("warped", "warped_id", "warped_depth", "proxy_id", "proxy_depth", "proxy_back_depth")
        self._hole_pass = objects.fullscreen(
            HOLE_FRAGMENT_SHADER, id_scale=ID_SCALE, **{name: unit for unit, name in enumerate(units)}
        )

    def set_boxes(self, box_min: np.ndarray, box_max: np.ndarray, object_ids: np.ndarray) -> None:
        """The proxy boxes (B, 3) in their objects' coordinates, and each box's object."""
        data = np.column_stack([box_min, box_max, object_ids]).astype(np.float32)
        if self._proxy_vao is not None:
            self._proxy_vao.release()
        self._boxes.orphan(max(data.nbytes, 28))
        self._boxes.write(data.tobytes())
        self._box_count = len(data)
        self._proxy_vao = self.ctx.vertex_array(self._proxy_program, [(self._boxes, "3f 3f 1f/i", "box_min", "box_max", "box_object")])

    def find(
        self,
        object_to_clip: np.ndarray,
        warped: IdImage,
        max_level: int,
        moved: set[int],
    ) -> tuple[np.ndarray, np.ndarray]:
        """Draw the proxies with per-object matrices (objects, 4, 4) and classify the warp's
        (colour, id, depth) textures, given the objects that moved since the client drew them:
        (hole level + 1 or 0, proxy object) per pixel, OpenGL rows."""
        ctx = self.ctx
        gl.write_matrix(self._proxy_program, "object_to_clip", object_to_clip)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        self._front_fbo.use()
        self._front_fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self._proxy_vao.render(moderngl.TRIANGLES, vertices=36, instances=self._box_count)
        self._back_fbo.use()
        self._back_fbo.clear(depth=1.0)
        ctx.enable(moderngl.CULL_FACE)
        # an OpenGL projection turns right-handed eye space into left-handed clip space (negative
        # determinant) and keeps outward faces towards the viewer counter-clockwise; one that does
        # not mirror z turns them clockwise
        ctx.front_face = "ccw" if np.linalg.det(object_to_clip[0]) < 0 else "cw"
        ctx.cull_face = "front"
        self._proxy_vao.render(moderngl.TRIANGLES, vertices=36, instances=self._box_count)
        ctx.disable(moderngl.CULL_FACE | moderngl.DEPTH_TEST)
        self._hole_fbo.use()
        proxy_maps = (self.proxy_id, self.proxy_depth, self.proxy_back_depth)
        for unit, texture in enumerate((warped.colour, warped.object_id, warped.depth, *proxy_maps)):
            texture.use(unit)
        self._hole_pass.program["max_level"].value = max_level
        self._hole_pass.program["moved"].value = sum(1 << i for i in moved)
        self._hole_pass.render(moderngl.TRIANGLES, vertices=3)
        w, h = self.size
        holes = np.frombuffer(self.holes.read(), dtype=np.uint8).reshape(h, w, 4)
        proxy = np.frombuffer(self.proxy_id.read(), dtype=np.uint16).reshape(h, w)
        return holes[:, :, 0].copy(), proxy.astype(np.int64)

    def release(self) -> None:
        if self._proxy_vao is not None:
            self._proxy_vao.release()
        self._objects.release()
