"""The adaptive warp grid (Schollmeyer et al., section 4.1): blocks of client pixels that show one
flat, connected surface patch are warped together as one quad instead of a point per pixel.

A surface-estimation quadtree is built bottom-up over tiles of GRID_TILE pixels: a node (an aligned
square of 2^l pixels) is a surface patch if all its pixels show one object, every pair of
neighbouring pixels inside it is connected (their depth difference is what their depth slopes
predict, so no depth discontinuity lies between them), and every three neighbouring pixels inside
it are collinear (second difference of depth below GRID_FLATNESS: the patch is flat, so its
corners' depths follow one plane). The grid takes, top down, the largest nodes that are patches;
what is left goes down to single pixels, each its own quad. NDC depth is an affine function of
the pixel position on a plane under any projection, so the tests work for perspective views too.

The quadtree is built on the CPU (numpy) once per client frame, from the client's surface
(`rig.render.warp_client.ClientTarget.surface`); the seeds build it on the GPU.
"""

from __future__ import annotations

import numpy as np

GRID_TILE = 32
"""The largest cell, in client pixels a side (the seeds' tile)."""
GRID_FLATNESS = 2e-4
"""Largest second difference (and connection mismatch) of NDC depth between neighbouring pixels
within a cell."""


def _connected(z: np.ndarray, slope: np.ndarray, ids: np.ndarray, pixels: int, axis: int) -> np.ndarray:
    """Per pixel, whether it connects to its next neighbour along `axis` (False at the far edge)."""
    nxt = [slice(None), slice(None)]
    nxt[axis] = slice(1, None)
    cur = [slice(None), slice(None)]
    cur[axis] = slice(0, -1)
    nxt, cur = tuple(nxt), tuple(cur)
    predicted = 0.5 * (slope[cur] + slope[nxt]) * 2.0 / pixels
    ok = (ids[cur] == ids[nxt]) & (np.abs(z[nxt] - z[cur] - predicted) < GRID_FLATNESS)
    pad = [(0, 0), (0, 0)]
    pad[axis] = (0, 1)
    return np.pad(ok, pad, constant_values=False)


def _collinear(z: np.ndarray, ids: np.ndarray, axis: int) -> np.ndarray:
    """Per pixel, whether it and its two neighbours along `axis` are one object on a line (False at edges)."""
    before = np.roll(z, 1, axis=axis)
    after = np.roll(z, -1, axis=axis)
    ok = (np.abs(before - 2.0 * z + after) < GRID_FLATNESS) & (np.roll(ids, 1, axis=axis) == ids) & (np.roll(ids, -1, axis=axis) == ids)
    edge = [slice(None), slice(None)]
    for index in (0, -1):
        edge[axis] = index
        ok[tuple(edge)] = False
    return ok


def _patch_nodes(ids: np.ndarray, tests: dict[str, np.ndarray], side: int) -> np.ndarray:
    """(rows, cols) of whether each aligned side x side node is a surface patch."""
    h, w = ids.shape
    rows, cols = h // side, w // side

    def blocks(a: np.ndarray) -> np.ndarray:
        return a.reshape(rows, side, cols, side)

    b = blocks(ids)
    nodes = b.min(axis=(1, 3)) == b.max(axis=(1, 3))
    if side >= 2:
        nodes &= blocks(tests["connected_x"])[:, :, :, : side - 1].all(axis=(1, 3))
        nodes &= blocks(tests["connected_y"])[:, : side - 1].all(axis=(1, 3))
    if side >= 3:
        nodes &= blocks(tests["collinear_x"])[:, :, :, 1 : side - 1].all(axis=(1, 3))
        nodes &= blocks(tests["collinear_y"])[:, 1 : side - 1].all(axis=(1, 3))
    return nodes


def grid_cells(surface: np.ndarray, tile: int = GRID_TILE) -> np.ndarray:
    """The adaptive grid of a client surface (h, w, 4) float32 = (NDC depth, depth slope x, depth
    slope y, object id), OpenGL rows: cells (n, 3) int32 of (x, y, side) in client pixels, which
    tile the image without overlap, largest first."""
    h, w = surface.shape[:2]
    padded = (-(-h // tile) * tile, -(-w // tile) * tile)
    z = np.zeros(padded)
    slope_x, slope_y = np.zeros(padded), np.zeros(padded)
    ids = np.full(padded, -1, dtype=np.int64)  # padding is no object: no patch reaches into it
    z[:h, :w], slope_x[:h, :w], slope_y[:h, :w] = surface[:, :, 0], surface[:, :, 1], surface[:, :, 2]
    ids[:h, :w] = np.rint(surface[:, :, 3]).astype(np.int64)
    tests = {
        "connected_x": _connected(z, slope_x, ids, w, axis=1),
        "connected_y": _connected(z, slope_y, ids, h, axis=0),
        "collinear_x": _collinear(z, ids, axis=1),
        "collinear_y": _collinear(z, ids, axis=0),
    }
    taken = np.zeros(padded, dtype=bool)
    cells = []
    side = tile
    while side >= 1:
        free = ~taken.reshape(padded[0] // side, side, padded[1] // side, side).any(axis=(1, 3))
        chosen = _patch_nodes(ids, tests, side) & free
        taken |= np.repeat(np.repeat(chosen, side, axis=0), side, axis=1)
        rows, cols = np.nonzero(chosen)
        inside = (rows * side < h) & (cols * side < w)
        rows, cols = rows[inside], cols[inside]
        cells.append(np.column_stack([cols * side, rows * side, np.full(len(rows), side)]))
        side //= 2
    return np.concatenate(cells).astype(np.int32)
