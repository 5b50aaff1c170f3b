"""Films of a flashing light made from the exact model, for testing the shutter estimator against
known readouts and exposures (given to tests as the ``flash_film`` fixture).

Row y of frame k is exposed over [t_k + y L, t_k + y L + E] (L = readout / height; a camera
reading from the bottom starts row y at (height - 1 - y) L). Its level is the dark level plus the
light's level times the time the light was on during that window over E, computed here by
summing the overlap with each on-interval (independently of the estimator's closed form). A
display's rows switch one after another: panel row v of h (0 at the top) is lit (v + 0.5) / h of
its scan-out later than the first, counted from the bottom when it scans bottom-up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest


@dataclass(frozen=True)
class Panel:
    """A display flashing full-field, seen in camera rows [top, top + rows)."""

    refresh_hz: float
    top: int
    rows: int
    direction: str = "top-down"
    scanout_fraction: float = 1.0


@dataclass(frozen=True)
class FlashFilm:
    """Times in s, levels in 8-bit digital numbers before clipping. ``light`` is the rectangle
    (x, y, w, h) the light fills (None: the whole frame; a panel's rows: its rows, every column);
    ``vignette`` the share of its level the light loses from its centre to its corners."""

    fps: float = 120.0
    readout_s: float = 6e-3
    exposure_s: float = 1e-3
    flash_hz: float = 300.0
    duty: float = 0.25
    phase_s: float = 1.3e-3
    duration_s: float = 1.5
    width: int = 24
    height: int = 160
    light: tuple[int, int, int, int] | None = None
    dark_dn: float = 12.0
    on_dn: float = 150.0
    vignette: float = 0.0
    noise_dn: float = 1.0
    jitter_s: float = 0.0
    bottom_up: bool = False
    panel: Panel | None = None
    seed: int = 0

    @property
    def times(self) -> np.ndarray:
        rng = np.random.default_rng(self.seed + 1)
        count = int(round(self.duration_s * self.fps))
        return np.arange(count) / self.fps + rng.uniform(-self.jitter_s, self.jitter_s, count)

    def on_shares(self, times: np.ndarray) -> np.ndarray:
        """(frames, rows): the share of each row's exposure the light was on."""
        rows = np.arange(self.height, dtype=np.float64)
        line = self.readout_s / self.height
        starts = times[:, None] + (self.height - 1 - rows if self.bottom_up else rows)[None, :] * line
        light_delay = self._scan_delays(rows)[None, :]
        period = 1.0 / self.flash_hz
        first = np.floor((starts - light_delay - self.phase_s) / period) - 1
        on = np.zeros_like(starts)
        for j in range(int(np.ceil(self.exposure_s / period)) + 3):
            begin = self.phase_s + light_delay + (first + j) * period
            end = begin + self.duty * period
            on += np.clip(np.minimum(starts + self.exposure_s, end) - np.maximum(starts, begin), 0.0, None)
        return on / self.exposure_s

    def _scan_delays(self, rows: np.ndarray) -> np.ndarray:
        if self.panel is None:
            return np.zeros_like(rows)
        p = self.panel
        index = rows - p.top if p.direction == "top-down" else p.top + p.rows - 1 - rows
        return (index + 0.5) / p.rows * p.scanout_fraction / p.refresh_hz

    def _light_map(self) -> np.ndarray:
        """(rows, columns): the light's level on each pixel when fully on."""
        x, y, w, h = self.light or ((0, self.panel.top, self.width, self.panel.rows) if self.panel else (0, 0, self.width, self.height))
        level = np.zeros((self.height, self.width))
        ys, xs = np.mgrid[y : y + h, x : x + w]
        radius = np.hypot((ys + 0.5 - y - h / 2) / (h / 2), (xs + 0.5 - x - w / 2) / (w / 2)) / np.sqrt(2)
        level[y : y + h, x : x + w] = self.on_dn * (1.0 - self.vignette * radius**2)
        return level

    def frames(self) -> tuple[np.ndarray, np.ndarray]:
        """The film as uint8 frames (N, H, W), and the frames' times."""
        times = self.times
        shares = self.on_shares(times)
        rng = np.random.default_rng(self.seed)
        images = self.dark_dn + shares[:, :, None] * self._light_map()[None, :, :]
        images += rng.normal(0.0, self.noise_dn, images.shape)
        return np.clip(np.rint(images), 0, 255).astype(np.uint8), times


@pytest.fixture
def flash_film() -> type[FlashFilm]:
    """The film class; call it with the fields to change from the defaults."""
    return FlashFilm


@pytest.fixture
def panel() -> type[Panel]:
    return Panel
