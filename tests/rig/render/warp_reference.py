"""A numpy reference of the warp server, for checking the GL warp on small images: the point-splat
warp, the two-view arbitration, the hole levels and the depth-aware low-pass fill.

The warp follows the equations in `rig.render.warp_matrices` and OpenGL's rules for what the GL
warp leaves to the pipeline: points in draw order (client pixel index, OpenGL rows), a point
outside the clip volume dropped, a square splat of side s covering the pixels whose centres lie in
[x - s/2, x + s/2) x [y - s/2, y + s/2) around its window position, and a `<` depth test against a
cleared depth of 1, so of equal depths the first drawn wins.
"""

from __future__ import annotations

import numpy as np

from rig.render.scene import BACKGROUND_ID
from rig.render.warp_matrices import jacobian, pixel_ndc, splat_size


def depth_slopes(ndc_depth: np.ndarray, object_id: np.ndarray) -> np.ndarray:
    """(h, w, 2) d(NDC depth)/d(NDC x, y): per axis the smaller one-sided difference to a neighbour
    showing the same object, 0 where neither neighbour does."""
    h, w = ndc_depth.shape
    slopes = np.zeros((h, w, 2))
    for axis, pixels in ((1, w), (0, h)):
        best = np.full((h, w), np.inf)
        for side in (-1, 1):
            neighbour_depth = np.roll(ndc_depth, -side, axis=axis)
            neighbour_id = np.roll(object_id, -side, axis=axis)
            valid = neighbour_id == object_id
            edge = [slice(None), slice(None)]
            edge[axis] = slice(-1, None) if side == 1 else slice(0, 1)
            valid[tuple(edge)] = False
            difference = np.where(valid, side * (neighbour_depth - ndc_depth), np.inf)
            best = np.where(np.abs(difference) < np.abs(best), difference, best)
        slopes[:, :, 1 - axis] = np.where(np.isfinite(best), best, 0.0) * pixels / 2.0
    return slopes


def reference_warp(
    colour: np.ndarray,
    object_id: np.ndarray,
    depth: np.ndarray,
    matrices: np.ndarray,
    server_size: tuple[int, int],
    max_splat: float,
    background_ndc_z: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Warp one client view: colour (h, w, 4) uint8, object_id (h, w), window depth (h, w) in
    [0, 1], all in OpenGL rows, with per-object matrices (objects, 4, 4), to `server_size` = (w, h).

    Returns (colour (H, W, 4) uint8 with alpha 255 where something was warped, 0 elsewhere;
    window depth (H, W), 1 where nothing was), in OpenGL rows.
    """
    h, w = object_id.shape
    sw, sh = server_size
    x, y = pixel_ndc((w, h))
    ndc_depth = depth.astype(np.float64) * 2.0 - 1.0
    points = np.stack(
        [np.broadcast_to(x, (h, w)), np.broadcast_to(y[:, None], (h, w)), ndc_depth, np.ones((h, w))], axis=-1
    ).reshape(-1, 4)
    ids = object_id.reshape(-1)
    slopes = depth_slopes(ndc_depth, object_id).reshape(-1, 2)
    slopes[ids == BACKGROUND_ID] = 0.0
    warped = np.empty_like(points)
    sizes = np.empty(len(points))
    for i in np.unique(ids):
        chosen = ids == i
        warped[chosen] = points[chosen] @ matrices[i].T
        sizes[chosen] = splat_size(jacobian(matrices[i], points[chosen], slopes[chosen]), (w, h), server_size, max_splat)
    background = ids == BACKGROUND_ID
    warped[background, 2] = background_ndc_z * warped[background, 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        ndc = warped[:, :3] / warped[:, 3:4]
    inside = (warped[:, 3] > 0.0) & np.all(np.abs(ndc) <= 1.0, axis=1)
    order = np.flatnonzero(inside)
    window_x = (ndc[order, 0] + 1.0) / 2.0 * sw
    window_y = (ndc[order, 1] + 1.0) / 2.0 * sh
    window_depth = (ndc[order, 2] + 1.0) / 2.0
    size = sizes[order]

    targets, sources, depths = [], [], []
    for dy in range(int(size.max(initial=1.0))):
        for dx in range(int(size.max(initial=1.0))):
            within = (dx < size) & (dy < size)
            column = np.ceil(window_x - size / 2.0 - 0.5).astype(np.int64) + dx
            row = np.ceil(window_y - size / 2.0 - 0.5).astype(np.int64) + dy
            keep = within & (column >= 0) & (column < sw) & (row >= 0) & (row < sh)
            targets.append(row[keep] * sw + column[keep])
            sources.append(order[keep])
            depths.append(window_depth[keep])
    target = np.concatenate(targets)
    source = np.concatenate(sources)
    fragment_depth = np.concatenate(depths)
    passing = fragment_depth < 1.0
    target, source, fragment_depth = target[passing], source[passing], fragment_depth[passing]
    # per target pixel: nearest fragment, first drawn among equals
    ranked = np.lexsort((source, fragment_depth, target))
    first = ranked[np.r_[True, np.diff(target[ranked]) != 0]] if len(ranked) else ranked

    out_colour = np.zeros((sh * sw, 4), dtype=np.uint8)
    out_depth = np.ones(sh * sw)
    out_colour[target[first], :3] = colour.reshape(-1, 4)[source[first], :3]
    out_colour[target[first], 3] = 255
    out_depth[target[first]] = fragment_depth[first]
    return out_colour.reshape(sh, sw, 4), out_depth.reshape(sh, sw)


def arbitrate_views(first: tuple[np.ndarray, np.ndarray], second: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Two views' warps (colour (H, W, 4), depth (H, W)) composited as the server does: the second
    only where the first covered nothing."""
    (colour, depth), (colour2, depth2) = first, second
    empty = colour[:, :, 3] == 0
    return np.where(empty[:, :, np.newaxis], colour2, colour), np.where(empty, depth2, depth)


def hole_levels(
    warped: tuple[np.ndarray, np.ndarray, np.ndarray],
    proxy: tuple[np.ndarray, np.ndarray, np.ndarray],
    max_level: int,
    moved: set[int],
) -> np.ndarray:
    """Per pixel, 1 + the hole level (0 none) of a warp (colour (H, W, 4), object id, window depth)
    against a proxy map (object id, nearest front depth, nearest back depth), where the objects in
    `moved` moved since the client drew them; see `rig.render.warp_holes`."""
    colour, ids, depth = warped
    proxy_id, front, back = proxy
    on_object = proxy_id != BACKGROUND_ID
    covered = colour[:, :, 3] > 0
    either_moved = np.isin(ids, list(moved)) | np.isin(proxy_id, list(moved))
    levels = np.where(on_object & ~covered, 1, 0)
    if max_level >= 1:
        levels = np.where(on_object & covered & either_moved & (ids != proxy_id) & (depth > front), 2, levels)
    if max_level >= 2:
        levels = np.where(on_object & covered & either_moved & (ids == proxy_id) & (depth > back) & (levels == 0), 3, levels)
    return levels


def _reduce(level: np.ndarray) -> np.ndarray:
    """One step up the low-pass pyramid (see `rig.render.fill_shaders`): (h, w, 4) of (rgb, depth),
    depth 2 where nothing is."""
    h, w = level.shape[:2]
    rows, cols = -(-h // 2), -(-w // 2)
    r = np.minimum(2 * np.arange(rows)[:, None, None, None] + np.array([0, 1])[None, :, None, None], h - 1)
    c = np.minimum(2 * np.arange(cols)[None, None, :, None] + np.array([0, 1])[None, None, None, :], w - 1)
    block = level[r, c]  # (rows, 2, cols, 2, 4)
    block = block.transpose(0, 2, 1, 3, 4).reshape(rows, cols, 4, 4)
    valid = block[:, :, :, 3] < 1.5
    count = valid.sum(axis=2)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(valid, block[:, :, :, 3], 0.0).sum(axis=2) / count
        kept = valid & (block[:, :, :, 3] >= mean[:, :, None] - 1e-7)
        out = (block * kept[:, :, :, None]).sum(axis=2) / kept.sum(axis=2)[:, :, None]
    out[count == 0] = [0.0, 0.0, 0.0, 2.0]
    return out


def lowpass_fill(
    colour: np.ndarray, depth: np.ndarray, search_levels: int, background: tuple[float, float, float] = (0.0, 0.0, 0.0)
) -> np.ndarray:
    """The depth-aware low-pass fill of a warp (colour (H, W, 4) uint8, alpha 0 for holes; window
    depth (H, W)), OpenGL rows: RGB float in [0, 1], each hole from the finest pyramid level whose
    bilinear neighbourhood holds something or from the next `search_levels`, whichever sample lies
    farthest."""
    h, w = depth.shape
    rgb = colour[:, :, :3].astype(np.float64) / 255.0
    hole = colour[:, :, 3] == 0
    levels = [np.dstack([rgb, np.where(hole, 2.0, depth)])]
    while max(levels[-1].shape[:2]) > 1:
        levels.append(_reduce(levels[-1]))
    result = rgb.copy()
    y, x = np.nonzero(hole)
    best = np.full((len(y), 4), [*background, -1.0])
    found = np.zeros(len(y), dtype=np.int64)
    for index, level in enumerate(levels[1:], start=1):
        at_x, at_y = (x + 0.5) / 2**index - 0.5, (y + 0.5) / 2**index - 0.5
        bx, by = np.floor(at_x).astype(np.int64), np.floor(at_y).astype(np.int64)
        fx, fy = at_x - bx, at_y - by
        total, weight = np.zeros((len(y), 4)), np.zeros(len(y))
        for dx, dy in ((0, 0), (1, 0), (0, 1), (1, 1)):
            texel = level[np.clip(by + dy, 0, level.shape[0] - 1), np.clip(bx + dx, 0, level.shape[1] - 1)]
            wgt = (fx if dx else 1.0 - fx) * (fy if dy else 1.0 - fy) * (texel[:, 3] < 1.5)
            total += texel * wgt[:, None]
            weight += wgt
        looking = (found <= search_levels) & (weight > 0)
        with np.errstate(invalid="ignore", divide="ignore"):
            sample = total / weight[:, None]
        better = looking & (sample[:, 3] > best[:, 3])
        best[better] = sample[better]
        found = np.where(looking | (found > 0), found + 1, found)
    result[y, x] = best[:, :3]
    return result
