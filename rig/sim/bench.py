"""Geometry of the simulated bench: where the camera sees the LED, the display and the sphere.

The camera looks at the pendulum plane. The left half of its image shows the real LED swinging;
the right half shows the display panel. The renderer's view is orthographic onto the same plane,
so a sphere drawn at the tracked position moves across the display as the LED moves across the
camera's left half (same direction, different scale and offset, which the analyser does not care
about).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from rig.sim.display import DisplayConfig
from rig.sim.pendulum import Pendulum

LED_SWING_FILL = 0.8
DISPLAY_SWING_FILL = 0.7
PANEL_WIDTH_FRACTION = 0.42
SPHERE_RADIUS_PX = 7.0
ROI_MARGIN_PX = 14.0

Rect = tuple[int, int, int, int]


class CameraImage(Protocol):
    """What the layout needs of the camera (a `rig.sim.camera.CameraConfig`): its image's size in pixels."""

    width: int
    height: int


@dataclass(frozen=True)
class BenchLayout:
    """Mappings between world metres, camera pixels and the display.

    px_per_m, led_centre_px and y_mid_m map a world point (x, y) on the LED side to camera pixel
    (cx + px_per_m * x, cy - px_per_m * (y - y_mid_m)). The display shows world x in
    [-half_width_m, half_width_m] around (0, y_mid_m) through `world_to_clip`, and appears in the
    camera image in the rectangle `panel` = (x, y, w, h) pixels.
    """

    camera_width: int
    camera_height: int
    px_per_m: float
    led_centre_px: tuple[float, float]
    y_mid_m: float
    panel: Rect
    display_width: int
    display_height: int
    half_width_m: float
    world_to_clip: np.ndarray
    sphere_radius_m: float
    led_roi: Rect
    sphere_roi: Rect

    def led_pixels(self, positions: np.ndarray) -> np.ndarray:
        """Camera pixel (x, y) of world positions (N, 3) on the LED side."""
        cx, cy = self.led_centre_px
        return np.stack(
            [cx + self.px_per_m * positions[:, 0], cy - self.px_per_m * (positions[:, 1] - self.y_mid_m)],
            axis=1,
        )

    def display_row_fraction(self, position: np.ndarray) -> float:
        """Row of the display (0 top, 1 bottom) where a world position is drawn."""
        clip = self.world_to_clip @ np.append(position, 1.0)
        return float(np.clip((1.0 - clip[1] / clip[3]) / 2.0, 0.0, 1.0))

    def panel_pixels(self, positions: np.ndarray) -> np.ndarray:
        """Camera pixel (x, y) where world positions (N, 3) appear on the display panel."""
        homogeneous = np.hstack([positions, np.ones((len(positions), 1))]) @ self.world_to_clip.T
        ndc = homogeneous[:, :2] / homogeneous[:, 3:4]
        px, py, pw, ph = self.panel
        return np.stack([px + (ndc[:, 0] + 1.0) / 2.0 * pw, py + (1.0 - ndc[:, 1]) / 2.0 * ph], axis=1)


def _bounding_rect(points: np.ndarray, margin: float, width: int, height: int) -> Rect:
    x0 = max(0, int(np.floor(points[:, 0].min() - margin)))
    y0 = max(0, int(np.floor(points[:, 1].min() - margin)))
    x1 = min(width, int(np.ceil(points[:, 0].max() + margin)))
    y1 = min(height, int(np.ceil(points[:, 1].max() + margin)))
    return (x0, y0, x1 - x0, y1 - y0)


def make_layout(pendulum: Pendulum, camera: CameraImage, display: DisplayConfig) -> BenchLayout:
    """Lay out the bench so the pendulum's full swing fills both halves of the camera image."""
    length = pendulum.length_m
    amplitude = np.radians(pendulum.config.amplitude_deg)
    swing_m = length * np.sin(amplitude)
    y_mid = -length * (1.0 + np.cos(amplitude)) / 2.0
    width, height = camera.width, camera.height

    px_per_m = LED_SWING_FILL * (width / 4.0) / swing_m
    led_centre = (width / 4.0, height / 2.0)

    half_width = swing_m / DISPLAY_SWING_FILL
    half_height = half_width * display.height / display.width
    world_to_clip = np.array(
        [
            [1.0 / half_width, 0.0, 0.0, 0.0],
            [0.0, 1.0 / half_height, 0.0, -y_mid / half_height],
            [0.0, 0.0, -1.0 / length, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )
    panel_w = int(round(PANEL_WIDTH_FRACTION * width))
    panel_h = int(round(panel_w * display.height / display.width))
    panel = (width // 2 + (width // 2 - panel_w) // 2, (height - panel_h) // 2, panel_w, panel_h)
    sphere_radius = SPHERE_RADIUS_PX * (2.0 * half_width) / panel_w

    arc = np.linspace(-amplitude, amplitude, 201)
    arc_positions = np.stack([length * np.sin(arc), -length * np.cos(arc), np.zeros_like(arc)], axis=1)
    layout = BenchLayout(
        camera_width=width,
        camera_height=height,
        px_per_m=px_per_m,
        led_centre_px=led_centre,
        y_mid_m=y_mid,
        panel=panel,
        display_width=display.width,
        display_height=display.height,
        half_width_m=half_width,
        world_to_clip=world_to_clip,
        sphere_radius_m=sphere_radius,
        led_roi=(0, 0, 0, 0),
        sphere_roi=(0, 0, 0, 0),
    )
    led_roi = _bounding_rect(layout.led_pixels(arc_positions), ROI_MARGIN_PX, width, height)
    px, py, pw, ph = panel
    sphere_points = layout.panel_pixels(arc_positions) - (px, py)
    sx, sy, sw, sh = _bounding_rect(sphere_points, ROI_MARGIN_PX + SPHERE_RADIUS_PX, pw, ph)
    return replace(layout, led_roi=led_roi, sphere_roi=(px + sx, py + sy, sw, sh))
