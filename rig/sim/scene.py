"""What the simulated camera films: the real LED on the pendulum and the light of the display panel.

The camera sees the LED where the bench layout (`rig.sim.layout`) puts the pendulum, as bright as
the board drives it, and the display panel as each of its rows emits at each instant (the
display's scan-out and sample-and-hold, `rig.sim.display`), in camera digital numbers.
"""

from __future__ import annotations

import numpy as np

from rig.devices.protocols import NO_IMAGE
from rig.sim.layout import BenchLayout
from rig.sim.board import SimulatedBoardConfig
from rig.sim.display import SimDisplay
from rig.sim.pendulum import Pendulum


class FilmedScene:
    """The light reaching the camera at given instants."""

    def __init__(
        self,
        pendulum: Pendulum,
        display: SimDisplay,
        layout: BenchLayout,
        display_black_dn: float,
        display_white_dn: float,
        board: SimulatedBoardConfig | None,
    ) -> None:
        self.pendulum = pendulum
        self.display = display
        self.layout = layout
        self.panel = layout.panel
        self._black = display_black_dn
        self._white = display_white_dn
        self._board = board
        self._rows = (np.arange(layout.panel[3]) + 0.5) / layout.panel[3]
        self._panels: dict[int, np.ndarray] = {}

    @property
    def settled_until(self) -> float:
        """Until when the scene's light is known: the display's content is decided up to there."""
        return self.display.settled_until

    def led_pixels(self, instants: np.ndarray) -> np.ndarray:
        """Where the camera sees the LED at each instant, (S, 2) pixels."""
        return self.layout.led_pixels(self.pendulum.led_position(instants))

    def led_levels(self, instants: np.ndarray) -> np.ndarray | None:
        """The LED's drive level 0..255 at each instant; None for an LED always fully on."""
        return self._board.led_level(instants) if self._board is not None else None

    def panel_light(self, starts: np.ndarray, exposure: float) -> np.ndarray:
        """The display panel's light averaged over each panel row's exposure [start, start + exposure]
        (`starts`, one per panel row from the top: a rolling shutter exposes lower rows later):
        each refresh a row shows counts for exactly the time it shows it during the row's exposure
        (scan-out), so where a refresh switches inside an exposure is not rounded to an instant."""
        refresh, shown = self.refresh_shares(starts, exposure)
        display = self.display
        # Only the last few refreshes can be on screen: look them up without copying all of content.
        oldest = max(int(refresh.min()), 0)
        recent = np.asarray(display.content[oldest:])
        image_ids = np.where(refresh >= 0, recent[np.clip(refresh - oldest, 0, len(recent) - 1)], NO_IMAGE)
        _, _, pw, ph = self.panel
        light = np.zeros((ph, pw), dtype=np.float32)
        for image_id in np.unique(image_ids):
            weight = np.where(image_ids == image_id, shown, 0.0).sum(axis=0).astype(np.float32)
            image = self._panel_image(int(image_id)) if image_id != NO_IMAGE else self._black
            light += weight[:, None] * image
        return light

    def refresh_shares(self, starts: np.ndarray, exposure: float) -> tuple[np.ndarray, np.ndarray]:
        """The refreshes each panel row shows during its exposure from `starts` (one per panel row)
        for `exposure`, (K, rows), and the share of the exposure each shows there, (K, rows)."""
        display = self.display
        start = np.asarray(starts, dtype=np.float64)
        end = start + exposure
        first = display.refresh_shown(start, self._rows)
        last = display.refresh_shown(end, self._rows)
        refresh = first[None, :] + np.arange(int((last - first).max()) + 1)[:, None]
        begins = display.vblank_time(refresh) + display.scanout_delay(self._rows)[None, :]
        shown = np.clip(np.minimum(begins + display.period_s, end) - np.maximum(begins, start), 0.0, None) / exposure
        return refresh, shown

    def _panel_image(self, image_id: int) -> np.ndarray:
        """The display image `image_id` as the camera sees it on the panel, in digital numbers."""
        if image_id not in self._panels:
            for old in [i for i in self._panels if i not in self.display.images]:
                del self._panels[old]
            import cv2  # here, not above: a scene's settings are read without OpenCV

            _, _, pw, ph = self.panel
            grey = cv2.cvtColor(np.ascontiguousarray(self.display.images[image_id]), cv2.COLOR_RGB2GRAY)
            panel = cv2.resize(grey, (pw, ph), interpolation=cv2.INTER_AREA).astype(np.float32)
            self._panels[image_id] = self._black + panel * np.float32((self._white - self._black) / 255.0)
        return self._panels[image_id]
