"""Geometry of the simulated bench: where the camera sees the LED, the display and the sphere.

The camera looks at the pendulum plane. Part of its image shows the real LED swinging, another
part the display panel; the bench's layout (`Placement`) says where, as fractions of the frame:

* ``side-by-side`` (the default): the LED's swing centred in the left half, the panel in the right
  half, both at mid-height;
* ``led-above`` / ``led-below``: the LED's swing left of centre and 35 % of the frame's height
  above / below the panel's centre, as a phone filming a lab bench often sees them;
* ``LX,LY,LW/DX,DY,DW``: the LED swing's centre (LX, LY) and width LW, then the panel's centre
  (DX, DY) and width DW, x and widths as fractions of the frame's width, y of its height (the
  default is ``0.25,0.5,0.4/0.75,0.5,0.42``). The panel keeps the display's aspect ratio; both must
  lie inside the frame, apart.

The renderer's view is orthographic onto the same plane, so a sphere drawn at the tracked position
moves across the display as the LED moves across its part of the image (same direction, different
scale and offset, which the analyser does not care about).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from rig.errors import ConfigError
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import Pendulum
from rig.sim.placement import DEFAULT_LAYOUT, Placement, placement

DISPLAY_SWING_FILL = 0.7
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

    def mean_rows(self, positions: np.ndarray) -> tuple[float, float]:
        """The mean row (index, 0 at the top) of the LED and of the sphere drawn at world positions
        (N, 3), as fractions of the frame's height: a rolling shutter exposes a row at that
        fraction of its readout after row 0."""
        led = self.led_pixels(positions)[:, 1]
        sphere = self.panel_pixels(positions)[:, 1]
        return float(np.mean(led) - 0.5) / self.camera_height, float(np.mean(sphere) - 0.5) / self.camera_height

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


def make_layout(pendulum: Pendulum, camera: CameraImage, display: DisplayConfig, layout: str = DEFAULT_LAYOUT) -> BenchLayout:
    """Lay out the bench as `layout` places it (`placement`): the LED's full swing as wide as its
    placement's width, the display's as wide as 70 % of the panel; ConfigError where the LED's
    swing or the panel leaves the frame or they overlap."""
    place = placement(layout)
    length = pendulum.length_m
    amplitude = np.radians(pendulum.config.amplitude_deg)
    swing_m = length * np.sin(amplitude)
    y_mid = -length * (1.0 + np.cos(amplitude)) / 2.0
    width, height = camera.width, camera.height

    led_x, led_y, led_width = place.led
    px_per_m = led_width * width / 2.0 / swing_m
    led_centre = (led_x * width, led_y * height)

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
    panel_x, panel_y, panel_width = place.display
    panel_w = int(round(panel_width * width))
    panel_h = int(round(panel_w * display.height / display.width))
    panel = (int(np.floor(panel_x * width - panel_w / 2)), int(np.floor(panel_y * height - panel_h / 2)), panel_w, panel_h)
    sphere_radius = SPHERE_RADIUS_PX * (2.0 * half_width) / panel_w

    arc = np.linspace(-amplitude, amplitude, 201)
    arc_positions = np.stack([length * np.sin(arc), -length * np.cos(arc), np.zeros_like(arc)], axis=1)
    mapped = BenchLayout(
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
    led_roi = _bounding_rect(mapped.led_pixels(arc_positions), ROI_MARGIN_PX, width, height)
    _check_fits(mapped.led_pixels(arc_positions), panel, led_roi, layout_name=layout, width=width, height=height)
    px, py, pw, ph = panel
    sphere_points = mapped.panel_pixels(arc_positions) - (px, py)
    sx, sy, sw, sh = _bounding_rect(sphere_points, ROI_MARGIN_PX + SPHERE_RADIUS_PX, pw, ph)
    return replace(mapped, led_roi=led_roi, sphere_roi=(px + sx, py + sy, sw, sh))


def _check_fits(led_path: np.ndarray, panel: Rect, led_roi: Rect, layout_name: str, width: int, height: int) -> None:
    """ConfigError unless the LED's swing (with its spot) and the panel lie inside the frame, apart."""
    reach = 3.0
    px, py, pw, ph = panel
    if (
        led_path[:, 0].min() - reach < 0 or led_path[:, 0].max() + reach > width
        or led_path[:, 1].min() - reach < 0 or led_path[:, 1].max() + reach > height
    ):
        raise ConfigError(f"layout {layout_name!r} puts the LED's swing partly outside the {width}x{height} frame")
    if px < 0 or py < 0 or px + pw > width or py + ph > height:
        raise ConfigError(f"layout {layout_name!r} puts the display panel partly outside the {width}x{height} frame")
    lx, ly, lw, lh = led_roi
    if lx < px + pw and px < lx + lw and ly < py + ph and py < ly + lh:
        raise ConfigError(f"layout {layout_name!r} puts the LED's swing over the display panel; move them apart")
