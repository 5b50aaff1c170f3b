"""The renderer plug-in protocol.

A renderer is the system under test: it turns predicted poses into display images. The session
drives it on the rig clock (virtual in simulation) and never looks inside it.

Two kinds of frames exist, as in the seed papers' display-layer architecture:

* **application frames** are rendered at the renderer's own pace. The session calls
  `render_app_frame` when the renderer is ready for the next one (a direct renderer: when the
  previous frame has been shown; a warp client: as soon as the previous frame is finished); the
  renderer asks the predictor (through `request.predict`) for the pose it wants, draws, and
  reports what that cost. The frame counts as finished at `t_start + cost_s`.
* **display frames** happen at every vertical blank. A renderer with `per_display_frame = True`
  (a warp renderer) composes a new image for each of them in `render_display_frame`; a renderer
  with `per_display_frame = False` (the direct renderer) returns its image with the application
  frame, and the display repeats that image until the next application frame is ready.

Images are RGB, uint8, shape (height, width, 3), row 0 at the top of the display (the row that is
scanned out first). A renderer reports what its work took on this machine (`cost_s`, wall
seconds); whether the run's clock charges that measured cost or a modelled one is the session's
cost model (`rig.session.timing`), not the renderer's business.

Third-party renderers are classes registered under the entry-point group `rig.renderers`; the
class is constructed without arguments and then `open`ed with a `RenderSetup`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol, runtime_checkable

import numpy as np

from predictors import Pose

PredictFn = Callable[[float], Pose]


@dataclass(frozen=True)
class RenderSetup:
    """What a renderer needs to know once, before the first frame.

    world_to_clip maps homogeneous world coordinates (metres) to OpenGL clip space; the display
    shows clip x, y in [-1, 1] with +y at the top row. wait_for_gpu asks the renderer to wait for
    the GPU to finish each frame, so that its reported cost is the whole work; a run that models
    its costs does not read them and lets the GPU run on.
    """

    width: int
    height: int
    world_to_clip: np.ndarray
    sphere_radius_m: float
    scene_triangles: int = 0
    scene_load: str = "soup"
    """what the load triangles make (`rig.render.gl.LOAD_SHAPES`)"""
    wait_for_gpu: bool = True
    seed: int = 0

    def row_fraction(self, position: np.ndarray) -> float:
        """The display row (0 top, 1 bottom) a world position is drawn at."""
        clip = self.world_to_clip @ np.append(position, 1.0)
        return float(np.clip((1.0 - clip[1] / clip[3]) / 2.0, 0.0, 1.0))


@dataclass(frozen=True)
class AppFrameRequest:
    index: int
    t_start: float
    t_photon: float
    predict: PredictFn


@dataclass(frozen=True)
class AppFrameResult:
    """What an application frame drew (the pose it used, its image where it has one: None for a
    renderer that composes at every refresh) and what the work took (s)."""

    cost_s: float
    pose: Pose
    image: np.ndarray | None


@dataclass(frozen=True)
class DisplayFrameRequest:
    """`app_frame` is the index of the newest application frame finished by now (-1: none yet);
    a renderer must not show a newer one, even if it has already drawn it."""

    index: int
    t_vblank: float
    t_photon: float
    predict: PredictFn
    app_frame: int


@dataclass(frozen=True)
class DisplayFrameResult:
    image: np.ndarray
    cost_s: float
    pose: Pose


@runtime_checkable
class Renderer(Protocol):
    name: str
    per_display_frame: bool

    def open(self, setup: RenderSetup) -> None: ...

    def render_app_frame(self, request: AppFrameRequest) -> AppFrameResult: ...

    def render_display_frame(self, request: DisplayFrameRequest) -> DisplayFrameResult: ...

    def close(self) -> None: ...
