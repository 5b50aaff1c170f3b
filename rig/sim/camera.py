"""A simulated high-speed camera filming the LED and the display (`SimCamera`).

Each frame integrates the scene over its exposure, adds a dark level and read noise, and saturates
at 255 like an 8-bit sensor. The LED is a bright Gaussian spot whose core saturates, as bright as
its drive level (0..255, the board's PWM) at each instant makes it, averaged over `subsamples`
instants of the exposure (motion blur); the display panel's rows are integrated exactly, each
refresh a row shows weighted by how long it shows it during the exposure (`rig.sim.scene`), so a
refresh that switches inside an exposure is seen where it switches, as a real sensor sees it.

What a lab's camera may do to the film besides (blur, a dim LED, a mirrored image, a lamp or a bar
in view, hidden frames, decimation) is the camera's `impairments` (`rig.sim.impairments`), applied
to each frame the sensor makes before it is recorded.

Read noise is drawn from a bank of precomputed noise fields at random offsets: full per-pixel
Gaussian draws would dominate the simulation's cost, and the analyser cannot tell the difference.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from declared import NON_NEGATIVE, POSITIVE, Flag, Range, check, setting
from rig.clock import Clock
from rig.devices.protocols import CameraFrame
from rig.errors import ConfigError
from rig.sim.impairments import FILM, FilmImpairments, FrameImpairer

if TYPE_CHECKING:
    from rig.sim.scene import FilmedScene

LED_SIGMA_PX = 2.2
LED_FULL_LEVEL = 255
_NOISE_BANK_SIZE = 8
_NOISE_PAD = 64


@dataclass(frozen=True)
class CameraConfig:
    fps: float = setting(240.0, "frames per second", "camera frame rate", Range(1.0, 10000.0, True, True), flag="--camera-fps")
    exposure_s: float | None = setting(
        None, "seconds", "camera exposure, at most one frame interval", POSITIVE, unset="the whole frame interval",
        flag=Flag(
            "--exposure", unit="frame intervals", per="fps", range=Range(0.0, 1.0, includes_high=True), default=1.0, metavar="F",
            help="camera exposure, as a fraction of the frame interval",
        ),
    )  # fmt: skip
    width: int = setting(640, "pixels", "sensor width", Range(64.0, includes_low=True))
    height: int = setting(480, "pixels", "sensor height", Range(48.0, includes_low=True))
    noise_dn: float = setting(2.0, "DN", "sensor read noise, in digital numbers", NON_NEGATIVE, flag=Flag("--noise-dn", group=FILM))
    dark_dn: float = setting(8.0, "DN", "the sensor's dark level", NON_NEGATIVE)
    led_peak_dn: float = setting(900.0, "DN", "the LED's peak before the sensor saturates", POSITIVE)
    display_black_dn: float = setting(6.0, "DN", "how bright the display's black films", NON_NEGATIVE)
    display_white_dn: float = setting(
        190.0, "DN", "how bright the display's white films: lower for a dim sphere", POSITIVE,
        flag=Flag("--display-white-dn", group=FILM),
    )  # fmt: skip
    subsamples: int = setting(8, "", "instants of each exposure averaged (motion blur)", Range(1.0, includes_low=True))
    impairments: FilmImpairments = field(default_factory=FilmImpairments)

    def __post_init__(self) -> None:
        check(self, ConfigError, "camera.")
        if self.exposure_s is not None and not self.exposure_s <= 1.0 / self.fps:
            raise ConfigError(
                f"camera exposure must be positive and at most one frame interval ({1e3 / self.fps:.3f} ms), "
                f"got {self.exposure_s * 1e3:.3f} ms"
            )

    @property
    def exposure(self) -> float:
        """Exposure time (s); the whole frame interval unless set.

        An exposure shorter than a whole number of refreshes sees each refresh's held image for a
        share of the exposure that depends on where the refresh falls in it; where camera and
        display rates are commensurate that share repeats, and the video's timing of the sphere is
        biased by up to half a refresh (``analysis.sampling`` works out by how much).
        """
        return self.exposure_s if self.exposure_s is not None else 1.0 / self.fps

    @property
    def film_fps(self) -> float:
        """The frame rate of the film: the camera's, or a decimated film's (every n-th frame)."""
        return self.fps / self.impairments.every_nth

    def subsample_offsets(self) -> np.ndarray:
        """Instants within the exposure (s from the frame's start) that are averaged."""
        return (np.arange(self.subsamples) + 0.5) / self.subsamples * self.exposure


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
    ) -> np.ndarray:
        """One frame: LED positions (S, 2) in pixels at each sub-instant, and the panel's mean light.

        `panel` is the display's light averaged over the exposure, in camera digital numbers,
        shape (h, w) of `panel_rect` = (x, y, w, h). `led_levels` (S,) is the LED's drive level
        0..255 at each sub-instant, its light scaled by level / 255; None is fully on throughout.
        """
        c = self.config
        image = np.full((c.height, c.width), c.dark_dn, dtype=np.float32)
        px, py, pw, ph = panel_rect
        image[py : py + ph, px : px + pw] += panel
        self._add_led(image, led_px, led_levels)
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


class SimCamera:
    """The simulated twin of a camera (`rig.devices.protocols.Camera`): exposures start at 0 s on
    the rig clock, one every 1 / fps, for `duration_s`; each is exposed as soon as everything it
    sees is known (the display's content up to the end of its exposure), and impaired. The film
    holds the frames the impairments keep (`film_times`), at `fps` (the film's rate).

    `impairment_seed` draws the frames whose sphere is hidden (`FilmImpairments.missing_fraction`).
    """

    def __init__(self, config: CameraConfig, scene: FilmedScene, duration_s: float, seed: int, impairment_seed: int) -> None:
        self.config = config
        self.fps = config.film_fps
        self.width = config.width
        self.height = config.height
        self.scene = scene
        self.frame_times = np.arange(0.0, duration_s - config.exposure, 1.0 / config.fps)
        self._impair = FrameImpairer(
            config.impairments,
            _background(config, scene.panel),
            {"led": scene.layout.led_roi, "sphere": scene.layout.sphere_roi},
            len(self.frame_times),
            impairment_seed,
        )
        self._seed = seed
        self._sensor: CameraSensor | None = None
        self._next = 0
        self._filmed = 0

    @property
    def film_times(self) -> np.ndarray:
        """When each frame of the film starts exposing (s)."""
        impairments = self.config.impairments
        return self.frame_times[impairments.first_frame :: impairments.every_nth]

    def connect(self, clock: Clock) -> None:
        self._sensor = CameraSensor(self.config, seed=self._seed)

    def poll(self) -> list[CameraFrame]:
        """Every frame whose exposure ends before the display's settled time, not returned before."""
        if self._sensor is None:
            raise RuntimeError("the simulated camera is not connected")
        exposure = self.config.exposure
        offsets = self.config.subsample_offsets()
        frames = []
        while self._next < len(self.frame_times) and self.frame_times[self._next] + exposure < self.scene.settled_until:
            t_start = float(self.frame_times[self._next])
            instants = self.frame_times[self._next] + offsets
            image = self._sensor.expose(
                self.scene.led_pixels(instants), self.scene.panel_light(t_start, exposure), self.scene.panel, self.scene.led_levels(instants)
            )
            filmed = self._impair(self._next, image)
            if filmed is not None:
                frames.append(CameraFrame(self._filmed, t_start, exposure, filmed))
                self._filmed += 1
            self._next += 1
        return frames

    def close(self) -> None:
        self._sensor = None


def _background(config: CameraConfig, panel: tuple[int, int, int, int]) -> np.ndarray:
    """The sensor's image of the rig with nothing in view lit: its dark level, and the panel's black."""
    image = np.full((config.height, config.width), config.dark_dn, dtype=np.float32)
    x, y, w, h = panel
    image[y : y + h, x : x + w] += config.display_black_dn
    return np.clip(np.rint(image), 0, 255).astype(np.uint8)
