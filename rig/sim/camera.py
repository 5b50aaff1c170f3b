"""A simulated high-speed camera filming the LED and the display (`SimCamera`).

Each frame integrates the scene over its exposure, adds a dark level and read noise, and saturates
at 255 like an 8-bit sensor. The LED is a bright Gaussian spot whose core saturates, as bright as
its drive level (0..255, the board's PWM) at each instant makes it, averaged over `subsamples`
instants of the exposure (motion blur); the display panel's rows are integrated exactly, each
refresh a row shows weighted by how long it shows it during the exposure (`rig.sim.scene`), so a
refresh that switches inside an exposure is seen where it switches, as a real sensor sees it.

A rolling shutter (`readout_s` > 0) exposes row y of H over [t + (y / H) readout, t + (y / H) readout
+ exposure] for a frame starting at t: every row sees the LED at its own instants and integrates
the panel's light over its own window, so a moving blob is skewed and a blob lower in the frame is
seen later, as a phone's or a webcam's sensor does. A camera with `frame_jitter_s` starts each
exposure after the first at its nominal time plus a seeded jitter, uniform in [-J/2, J/2], as a
phone's camera does; its film is then a container that stamps every frame (`rig.film_file`).

What a lab's camera may do to the film besides (blur, a dim LED, a mirrored image, a lamp or a bar
in view, hidden frames, decimation) is the camera's `impairments` (`rig.sim.impairments`), applied
to each frame the sensor makes before it is recorded.

Read noise is drawn from a bank of precomputed noise fields at random offsets: full per-pixel
Gaussian draws would dominate the simulation's cost, and the analyser cannot tell the difference.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from rig.clock import Clock
from rig.devices.protocols import CameraFrame, Fault
from rig.sim.impairments import FrameImpairer
from rig.sim.impairments_config import FilmImpairments
from rig.sim.camera_config import CameraConfig

if TYPE_CHECKING:
    from rig.sim.flash import FlashingLightScene
    from rig.sim.scene import FilmedScene

LED_SIGMA_PX = 2.2
LED_FULL_LEVEL = 255
_NOISE_BANK_SIZE = 8
_NOISE_PAD = 64
# Instants per frame at which the LED's path is looked at to bound the rows its spot can light.
_ROW_BOUND_INSTANTS = 16
_JITTER_STREAM = 7


class CameraSensor:
    """Turns the light arriving during one exposure into an 8-bit image."""

    def __init__(self, config: CameraConfig, seed: int) -> None:
        self.config = config
        self._rng = np.random.default_rng(seed)
        shape = (_NOISE_BANK_SIZE, config.height + _NOISE_PAD, config.width + _NOISE_PAD)
        self._noise = (self._rng.standard_normal(shape, dtype=np.float32) * config.noise_dn).astype(np.float32)

    def expose(
        self,
        led_px: np.ndarray,
        panel: np.ndarray,
        panel_rect: tuple[int, int, int, int],
        led_levels: np.ndarray | None = None,
        first_row: int | None = None,
    ) -> np.ndarray:
        """One frame: LED positions (S, 2) in pixels at each sub-instant, and the panel's mean light.

        `panel` is the display's light averaged over the exposure, in camera digital numbers,
        shape (h, w) of `panel_rect` = (x, y, w, h). `led_levels` (S,) is the LED's drive level
        0..255 at each sub-instant, its light scaled by level / 255; None is fully on throughout.
        With `first_row` (a rolling shutter) each row sees the LED at its own sub-instants:
        `led_px` is (R, S, 2) and `led_levels` (R, S), row first_row + r seeing entry r.
        """
        c = self.config
        image = np.full((c.height, c.width), c.dark_dn, dtype=np.float32)
        px, py, pw, ph = panel_rect
        image[py : py + ph, px : px + pw] += panel
        if first_row is None:
            self._add_led(image, led_px, led_levels)
        else:
            self._add_led_by_row(image, led_px, led_levels, first_row)
        k = self._rng.integers(_NOISE_BANK_SIZE)
        oy, ox = self._rng.integers(_NOISE_PAD, size=2)
        image += self._noise[k, oy : oy + c.height, ox : ox + c.width]
        return np.clip(np.rint(image), 0, 255).astype(np.uint8)

    def _add_led(self, image: np.ndarray, led_px: np.ndarray, led_levels: np.ndarray | None) -> None:
        scale = self.config.led_peak_dn / len(led_px)
        gain = None
        if led_levels is not None:
            levels = np.asarray(led_levels, dtype=np.float64)
            lit = levels > 0.0
            if not lit.any():
                return
            led_px, gain = led_px[lit], levels[lit] / LED_FULL_LEVEL
        reach = 5.0 * LED_SIGMA_PX
        x0 = int(max(0, np.floor(led_px[:, 0].min() - reach)))
        x1 = int(min(image.shape[1], np.ceil(led_px[:, 0].max() + reach)))
        y0 = int(max(0, np.floor(led_px[:, 1].min() - reach)))
        y1 = int(min(image.shape[0], np.ceil(led_px[:, 1].max() + reach)))
        if x1 <= x0 or y1 <= y0:
            return
        xs = np.arange(x0, x1, dtype=np.float32) + 0.5
        ys = np.arange(y0, y1, dtype=np.float32) + 0.5
        gx = np.exp(-0.5 * ((xs[None, :] - led_px[:, 0:1]) / LED_SIGMA_PX) ** 2)
        gy = np.exp(-0.5 * ((ys[None, :] - led_px[:, 1:2]) / LED_SIGMA_PX) ** 2)
        if gain is not None:
            gy = gy * gain[:, None]
        spot = np.einsum("sy,sx->yx", gy, gx) * scale
        image[y0:y1, x0:x1] += spot.astype(np.float32)

    def _add_led_by_row(self, image: np.ndarray, led_px: np.ndarray, led_levels: np.ndarray | None, first_row: int) -> None:
        """The LED's spot as a rolling shutter sees it: row first_row + r integrates the spot at the
        positions led_px[r] (S, 2) of its own sub-instants, each scaled by its level."""
        rows = first_row + np.arange(len(led_px))
        inside = (rows >= 0) & (rows < image.shape[0])
        rows, led_px = rows[inside], led_px[inside]
        if not len(rows):
            return
        gain = np.ones(led_px.shape[:2]) if led_levels is None else np.asarray(led_levels, dtype=np.float64)[inside] / LED_FULL_LEVEL
        reach = 5.0 * LED_SIGMA_PX
        x0 = int(max(0, np.floor(led_px[..., 0].min() - reach)))
        x1 = int(min(image.shape[1], np.ceil(led_px[..., 0].max() + reach)))
        if x1 <= x0:
            return
        xs = np.arange(x0, x1, dtype=np.float32) + 0.5
        gy = np.exp(-0.5 * (((rows[:, None] + 0.5) - led_px[..., 1]) / LED_SIGMA_PX) ** 2) * gain
        gx = np.exp(-0.5 * ((xs[None, None, :] - led_px[..., 0:1]) / LED_SIGMA_PX) ** 2)
        spot = np.einsum("rs,rsx->rx", gy, gx) * (self.config.led_peak_dn / led_px.shape[1])
        image[rows[0] : rows[-1] + 1, x0:x1] += spot.astype(np.float32)


class SimCamera:
    """The simulated twin of a camera (`rig.devices.protocols.Camera`): exposures start at 0 s on
    the rig clock, one every 1 / fps (each after the first moved by the jitter, if any), for
    `duration_s`; each is exposed as soon as everything it sees is known (the display's content up
    to the end of its last row's exposure), and impaired. The film holds the frames the impairments
    keep (`film_times`), at `fps` (the film's rate).

    `impairment_seed` draws the frames whose sphere is hidden (`FilmImpairments.missing_fraction`);
    `seed` the sensor's noise and the frame-timing jitter.
    """

    def __init__(self, config: CameraConfig, scene: FilmedScene | FlashingLightScene, duration_s: float, seed: int, impairment_seed: int) -> None:
        self.config = config
        self.fps = config.film_fps
        self.width = config.width
        self.height = config.height
        self.scene = scene
        jitter = config.frame_jitter_s
        self.frame_times = np.arange(0.0, duration_s - config.exposure - config.readout_s - jitter / 2, 1.0 / config.fps)
        if jitter > 0.0:
            shift = np.random.default_rng((seed, _JITTER_STREAM)).uniform(-jitter / 2, jitter / 2, len(self.frame_times))
            self.frame_times[1:] += shift[1:]
        self._impair = FrameImpairer(
            config.impairments,
            _background(config, scene.panel),
            {"led": scene.layout.led_roi, "sphere": scene.layout.sphere_roi},
            len(self.frame_times),
            impairment_seed,
        )
        self._panel_row_delays = config.row_delays(scene.panel[1] + np.arange(scene.panel[3]))
        self._seed = seed
        self._sensor: CameraSensor | None = None
        self._next = 0
        self._filmed = 0

    @property
    def film_times(self) -> np.ndarray:
        """When each frame of the film starts exposing (s): its row 0's exposure."""
        impairments = self.config.impairments
        return self.frame_times[impairments.first_frame :: impairments.every_nth]

    @property
    def frame_span_s(self) -> float:
        """From a frame's start to the end of its last row's exposure (s)."""
        return self.config.exposure + self.config.readout_s

    def connect(self, clock: Clock) -> None:
        self._sensor = CameraSensor(self.config, seed=self._seed)

    def poll(self) -> list[CameraFrame]:
        """Every frame whose exposure ends before the display's settled time, not returned before."""
        if self._sensor is None:
            raise RuntimeError("the simulated camera is not connected")
        c = self.config
        frames = []
        while self._next < len(self.frame_times) and self.frame_times[self._next] + self.frame_span_s < self.scene.settled_until:
            t_start = float(self.frame_times[self._next])
            panel = self.scene.panel_light(t_start + self._panel_row_delays, c.exposure)
            if c.readout_s > 0.0:
                first_row, led_px, levels = self._led_by_row(t_start)
                image = self._sensor.expose(led_px, panel, self.scene.panel, levels, first_row)
            else:
                instants = self.frame_times[self._next] + c.subsample_offsets()
                image = self._sensor.expose(self.scene.led_pixels(instants), panel, self.scene.panel, self.scene.led_levels(instants))
            filmed = self._impair(self._next, image)
            if filmed is not None:
                frames.append(CameraFrame(self._filmed, t_start, c.exposure, filmed, c.readout_s))
                self._filmed += 1
            self._next += 1
        return frames

    def _led_by_row(self, t_start: float) -> tuple[int, np.ndarray, np.ndarray | None]:
        """Where each row that the LED's spot can reach sees it during its own exposure: the first
        such row, the pixels (R, S, 2) and the drive levels (R, S) at each row's sub-instants."""
        c = self.config
        path = self.scene.led_pixels(t_start + np.linspace(0.0, self.frame_span_s, _ROW_BOUND_INSTANTS))[:, 1]
        reach = 5.0 * LED_SIGMA_PX + 1.0
        first = int(max(0, np.floor(path.min() - reach)))
        rows = np.arange(first, int(min(c.height, np.ceil(path.max() + reach))))
        instants = t_start + c.row_delays(rows)[:, None] + c.subsample_offsets()[None, :]
        pixels = self.scene.led_pixels(instants.ravel()).reshape(len(rows), c.subsamples, 2)
        levels = self.scene.led_levels(instants.ravel())
        return first, pixels, None if levels is None else levels.reshape(instants.shape)

    def fault(self) -> Fault | None:
        """None: the simulated camera films to the end."""
        return None

    def report(self) -> dict[str, Any]:
        return {"camera": "sim", "fps": self.fps, "frames": self._filmed}

    def close(self) -> None:
        self._sensor = None


def _background(config: CameraConfig, panel: tuple[int, int, int, int]) -> np.ndarray:
    """The sensor's image of the rig with nothing in view lit: its dark level, and the panel's black."""
    image = np.full((config.height, config.width), config.dark_dn, dtype=np.float32)
    x, y, w, h = panel
    image[y : y + h, x : x + w] += config.display_black_dn
    return np.clip(np.rint(image), 0, 255).astype(np.uint8)
