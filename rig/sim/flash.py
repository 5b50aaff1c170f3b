"""A calibration target for the simulated camera: a flashing light that shows its shutter's readout
and exposure (`rig calibrate-camera` measures them from the film).

Two targets, as a lab films them:

* ``light``: a white card lit by an LED flashing at `hz`, on for `duty` of each period from
  `phase_s`, fills the camera's view (the pendulum and the display are out of view). Each row gets
  the share of its own exposure window the LED was on, exactly, as bright as `level_dn` at the
  frame's centre and dimmer towards its corners (`vignette`, the share lost there), as a lens
  vignettes an evenly lit card.
* ``display``: the display, where the layout puts it, shows full-field white for the first
  ceil(N / 2) of every N refreshes and black for the rest (a program alternating white and black
  frames at N = 2): it flashes at refresh_hz / N, each of its rows switching as the scan-out
  reaches it, and the camera integrates each refresh a row shows exactly (`FilmedScene`). The
  pendulum's LED stays in view beside it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from rig.sim.layout import BenchLayout
from rig.sim.display import SimDisplay
from rig.sim.scene import FilmedScene
from rig.sim.flash_target import FlashTarget

class FlashingLightScene:
    """The ``light`` target as the camera sees it: a panel filling the frame whose rows are lit as
    the LED was on during each row's exposure; no LED in view."""

    def __init__(self, target: FlashTarget, layout: BenchLayout, display: SimDisplay) -> None:
        self.target = target
        self.layout = layout
        self.panel = (0, 0, layout.camera_width, layout.camera_height)
        self._display = display
        ys, xs = np.mgrid[0 : layout.camera_height, 0 : layout.camera_width] + 0.5
        corner = np.hypot((xs / layout.camera_width - 0.5), (ys / layout.camera_height - 0.5)) / math.hypot(0.5, 0.5)
        self._level = (target.level_dn * (1.0 - target.vignette * corner**2)).astype(np.float32)

    @property
    def settled_until(self) -> float:
        """As the bench's scene: frames are filmed as the run's clock reaches them."""
        return self._display.settled_until

    def led_pixels(self, instants: np.ndarray) -> np.ndarray:
        return np.zeros((*np.shape(instants), 2))

    def led_levels(self, instants: np.ndarray) -> np.ndarray:
        return np.zeros(np.shape(instants))

    def panel_light(self, starts: np.ndarray, exposure: float) -> np.ndarray:
        """Each row's light: its level times the share of [start, start + exposure] the LED was on."""
        return self._level * on_shares(np.asarray(starts, dtype=np.float64), exposure, self.target)[:, None].astype(np.float32)


class FlashingDisplayScene(FilmedScene):
    """The ``display`` target: the bench's scene (made from `scene`, `FilmedScene`'s arguments), its
    panel flashing full-field white and black."""

    def __init__(self, target: FlashTarget, *scene: Any) -> None:
        super().__init__(*scene)
        self.target = target

    def panel_light(self, starts: np.ndarray, exposure: float) -> np.ndarray:
        refresh, shown = self.refresh_shares(starts, exposure)
        white = (np.mod(refresh, self.target.refreshes) < math.ceil(self.target.refreshes / 2)) & (refresh >= 0)
        share = (shown * white).sum(axis=0).astype(np.float32)
        _, _, pw, ph = self.panel
        return np.repeat((self._black + share * (self._white - self._black))[:, None], pw, axis=1)


def on_shares(starts: np.ndarray, exposure: float, target: FlashTarget) -> np.ndarray:
    """The share of each window [start, start + exposure] during which the light, on for [phase +
    k period, phase + (k + duty) period) for every whole k, was on: the overlap with each such
    interval that can meet the window, summed."""
    period = 1.0 / target.hz
    first = np.floor((starts - target.phase_s) / period) - 1
    on = np.zeros_like(starts)
    for k in range(int(math.ceil(exposure / period)) + 3):
        begin = target.phase_s + (first + k) * period
        on += np.clip(np.minimum(starts + exposure, begin + target.duty * period) - np.maximum(starts, begin), 0.0, None)
    return on / exposure
