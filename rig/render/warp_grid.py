"""The adaptive warp grid (Schollmeyer et al., section 4.1): blocks of client pixels that show one
surface patch are warped together as one quad instead of a point per pixel.

A surface-estimation quadtree is built over tiles of GRID_TILE pixels: a node (an aligned square of
2^l pixels) is a surface patch if all its pixels show one object and the quad the warp draws for it
reproduces every pixel's depth closely enough that the difference cannot move the pixel by more
than GRID_REPROJECTION_PX when warped. The quad's depth is what the server draws
(`rig.render.warp_shaders`, the grid's vertex shader): each corner's depth from the plane of the
node's pixel in that corner, interpolated over the two triangles of a strip. The grid takes, top
down, the largest nodes that are patches; what is left goes down to single pixels, each its own quad.

How far a depth error moves a warped pixel depends on the pose change. Under a perspective view a
translation that moves a point at eye depth D by s pixels moves a point at D + dD by s D / (D + dD),
so the error is s |dD| / D to first order: a relative depth error, whatever the focal length. NDC
depth is affine in 1/D, z = a - b / D (a: the NDC depth of points at infinity), so |dD| / D =
|dz| / (a - z). The grid is built once per client frame, before the server's poses are known, so it
bounds s by the largest image motion the client frame is drawn to serve (its border, `motion_px`)
and a by the far end of the object's NDC depth range (`far_ndc`; a lies beyond the far plane for any
perspective, so this only overstates the error): a patch's depth error may be at most
GRID_REPROJECTION_PX / motion_px of (far_ndc - z) at each pixel. An orthographic view has no
parallax, so the bound holds there too; a rotation about the eye, or the load's spin about the
view axis, moves every depth alike. Depth
steps inside a node fail the bound unless their parallax is sub-pixel; a curved, finely tessellated
surface merges where its deviation from the quad is. The bound shrinks to nothing at the far end,
so no quad's depth leaves its object's range.

The quadtree is built on the CPU (numpy) once per client frame, from the client's surface
(`rig.render.warp_client.ClientTarget.surface`); the seeds build it on the GPU.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

GRID_TILE = 32
"""The largest cell, in client pixels a side (the seeds' tile)."""
GRID_REPROJECTION_PX = 0.5
"""Largest displacement, in pixels, that a patch's depth error may cause at the largest motion
served: the rounding a point splat makes anyway, which puts each warped pixel on the nearest pixel."""
GRID_DEPTH_RESOLUTION = 2.0**-20
"""Depth differences below this (NDC) count as none: the depth buffer's resolution and the float32
rounding of the surface's slopes, so an exact plane merges next to the far end too."""


def _quad_depth_error(z: np.ndarray, slope_x: np.ndarray, slope_y: np.ndarray, side: int, size: tuple[int, int]) -> np.ndarray:
    """(rows, side, cols, side): per pixel of each aligned side x side node, |pixel depth - the
    depth of the quad the grid's vertex shader draws for that node| (NDC)."""
    h, w = z.shape
    rows, cols = h // side, w // side

    def blocks(a: np.ndarray) -> np.ndarray:
        return a.reshape(rows, side, cols, side)

    zb, sxb, syb = blocks(z), blocks(slope_x), blocks(slope_y)
    corner = {}
    for cy in (0, 1):
        for cx in (0, 1):
            i, j = cy * (side - 1), cx * (side - 1)
            offset_x, offset_y = (2 * cx - 1) / size[0], (2 * cy - 1) / size[1]
            corner[cx, cy] = (zb[:, i, :, j] + sxb[:, i, :, j] * offset_x + syb[:, i, :, j] * offset_y)[:, None, :, None]
    centre = (np.arange(side) + 0.5) / side
    u, v = centre[None, None, None, :], centre[None, :, None, None]
    below = u + v <= 1.0  # the strip's triangle (0,0) (1,0) (0,1); the other is (1,0) (1,1) (0,1)
    z00, z10, z01, z11 = corner[0, 0], corner[1, 0], corner[0, 1], corner[1, 1]
    quad = np.where(
        below,
        z00 + u * (z10 - z00) + v * (z01 - z00),
        z11 + (1.0 - u) * (z01 - z11) + (1.0 - v) * (z10 - z11),
    )
    return np.abs(zb - quad)


def _patch_nodes(
    ids: np.ndarray, z: np.ndarray, slopes: tuple[np.ndarray, np.ndarray], tolerance: np.ndarray, side: int, size: tuple[int, int]
) -> np.ndarray:
    """(rows, cols) of whether each aligned side x side node is a surface patch."""
    h, w = ids.shape
    rows, cols = h // side, w // side
    b = ids.reshape(rows, side, cols, side)
    nodes = b.min(axis=(1, 3)) == b.max(axis=(1, 3))
    if side >= 2:
        error = _quad_depth_error(z, *slopes, side, size)
        nodes &= (error <= tolerance.reshape(rows, side, cols, side)).all(axis=(1, 3))
    return nodes


def grid_cells(
    surface: np.ndarray, motion_px: float, far_ndc: Sequence[float] | float = 1.0, tile: int = GRID_TILE
) -> np.ndarray:
    """The adaptive grid of a client surface (h, w, 4) float32 = (NDC depth, depth slope x, depth
    slope y, object id), OpenGL rows: cells (n, 3) int32 of (x, y, side) in client pixels, which
    tile the image without overlap, largest first.

    `motion_px`: the largest image motion, in client pixels, the frame is warped over; `far_ndc`:
    per object ID (or one for all), the NDC depth of the far end of its depth range (see the module
    docstring)."""
    if not motion_px > 0:
        raise ValueError(f"the grid's motion bound must be a positive number of pixels, got {motion_px!r}")
    h, w = surface.shape[:2]
    padded = (-(-h // tile) * tile, -(-w // tile) * tile)
    z = np.zeros(padded)
    slope_x, slope_y = np.zeros(padded), np.zeros(padded)
    ids = np.full(padded, -1, dtype=np.int64)  # padding is no object: no patch reaches into it
    z[:h, :w], slope_x[:h, :w], slope_y[:h, :w] = surface[:, :, 0], surface[:, :, 1], surface[:, :, 2]
    ids[:h, :w] = np.rint(surface[:, :, 3]).astype(np.int64)
    far = np.asarray(far_ndc, dtype=np.float64)
    far = far[ids[:h, :w]] if far.ndim else far
    tolerance = np.zeros(padded)
    tolerance[:h, :w] = GRID_REPROJECTION_PX / motion_px * np.maximum(far - z[:h, :w], 0.0)
    tolerance = np.maximum(tolerance, GRID_DEPTH_RESOLUTION)
    taken = np.zeros(padded, dtype=bool)
    cells = []
    side = tile
    while side >= 1:
        free = ~taken.reshape(padded[0] // side, side, padded[1] // side, side).any(axis=(1, 3))
        chosen = _patch_nodes(ids, z, (slope_x, slope_y), tolerance, side, (w, h)) & free
        taken |= np.repeat(np.repeat(chosen, side, axis=0), side, axis=1)
        rows, cols = np.nonzero(chosen)
        inside = (rows * side < h) & (cols * side < w)
        rows, cols = rows[inside], cols[inside]
        cells.append(np.column_stack([cols * side, rows * side, np.full(len(rows), side)]))
        side //= 2
    return np.concatenate(cells).astype(np.int32)
