"""How the warp server fills the level-0 holes left after the warp (`rig.render.fill_shaders`):

* "nearest": the colour of the farthest of the first covered pixels in 8 directions, one pass;
* "lowpass": the depth-aware low-pass pyramid of Schollmeyer et al. (section 5.2): each level
  averages the level below over 2x2 texels, leaving out holes and texels nearer than their mean
  depth, and a hole takes the finest level whose neighbourhood holds something. The seeds choose
  the level by searching the hole's border along the epipolar line; the pyramid's own coverage
  gives the same growth of the blur with the distance to the border without a search.

Both write the output image with alpha 0 where a hole was filled.
"""

from __future__ import annotations

import math

import moderngl
import numpy as np

from rig.errors import ConfigError
from rig.render import gl
from rig.render.fill_shaders import (
    NEAREST_FILL_FRAGMENT_SHADER,
    PYRAMID_BASE_FRAGMENT_SHADER,
    PYRAMID_REDUCE_FRAGMENT_SHADER,
    lowpass_fill_fragment_shader,
)

FILLS = ("nearest", "lowpass")
FILL_SEARCH_FRACTION = 1.0 / 16.0
"""A nearest fill searches this fraction of the display's larger side, in pixels, in each direction."""


def pyramid_sizes(size: tuple[int, int]) -> list[tuple[int, int]]:
    """The (w, h) of the low-pass pyramid's levels 0, 1, ... down to 1 x 1."""
    sizes = [size]
    while max(sizes[-1]) > 1:
        w, h = sizes[-1]
        sizes.append((max(1, math.ceil(w / 2)), max(1, math.ceil(h / 2))))
    return sizes


class HoleFill:
    """One fill (see the module docstring) for one image size, in one context."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int], kind: str, background: tuple[float, float, float]) -> None:
        if kind not in FILLS:
            raise ConfigError(f"the warp's hole fill must be one of {', '.join(FILLS)}, got {kind!r}")
        self.ctx = ctx
        self.kind = kind
        self._objects = objects = gl.GLObjects(ctx)
        self._levels: list[tuple[moderngl.Texture, moderngl.Framebuffer]] = []
        final = {"warped": 0, "background": background}
        if kind == "nearest":
            steps = int(np.ceil(FILL_SEARCH_FRACTION * max(size)))
            self._pass = objects.fullscreen(NEAREST_FILL_FRAGMENT_SHADER, warped_depth=1, max_steps=steps, **final)
        else:
            for level_size in pyramid_sizes(size):
                texture = objects.texture(level_size, 4, dtype="f4")
                self._levels.append((texture, objects.keep(ctx.framebuffer(color_attachments=[texture]))))
            self._base = objects.fullscreen(PYRAMID_BASE_FRAGMENT_SHADER, warped_depth=1)
            self._reduce = objects.fullscreen(PYRAMID_REDUCE_FRAGMENT_SHADER)
            levels = {f"level_{level}": level for level in range(1, len(self._levels))}
            self._pass = objects.fullscreen(lowpass_fill_fragment_shader(len(self._levels) - 1), **levels, **final)

    def fill(self, warped: moderngl.Texture, warped_depth: moderngl.Texture, output: moderngl.Framebuffer) -> None:
        """Fill the holes (alpha 0) of `warped` into `output`."""
        self.ctx.disable(moderngl.DEPTH_TEST)
        if self.kind == "lowpass":
            self._levels[0][1].use()
            warped.use(0)
            warped_depth.use(1)
            self._base.render(moderngl.TRIANGLES, vertices=3)
            for (finer, _), (_, coarser) in zip(self._levels, self._levels[1:]):
                coarser.use()
                finer.use(0)
                self._reduce.render(moderngl.TRIANGLES, vertices=3)
            for level, (texture, _) in enumerate(self._levels[1:], start=1):
                texture.use(level)
        output.use()
        warped.use(0)
        if self.kind == "nearest":
            warped_depth.use(1)
        self._pass.render(moderngl.TRIANGLES, vertices=3)

    def release(self) -> None:
        self._objects.release()
