"""A simulated camera's settings, each declared on its field: what the command line's options are made
from, without the simulation's numerical libraries (`rig.sim.camera` films with them)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from declared import Flag, Range, check, setting
from rig.errors import ConfigError
from rig.film_formats import CODECS, CONTAINERS, check_film_format, default_codec
from rig.sim.impairments_config import FILM, SENSOR_LEVELS, FilmImpairments

if TYPE_CHECKING:
    import numpy as np


@dataclass(frozen=True)
class CameraConfig:
    """A camera's frame rate, exposure (None: the whole frame interval), readout (0: a global
    shutter; else the time from row 0's exposure to the last row's), frame-timing jitter (0: a
    constant rate), size, sensor and film; `container` and `codec` are the film's file
    (`rig.film_file`: an MJPEG AVI, or H.264 or HEVC in an MP4 or a MOV)."""

    fps: float = setting(
        240.0, "frames per second", "camera frame rate: a webcam films tens of frames a second, a high-speed camera "
        "several thousand", Range(1.0, 10000.0, True, True), flag="--camera-fps",
    )  # fmt: skip
    exposure_s: float | None = setting(
        None, "seconds", "camera exposure, at most one frame interval", Range(0.0, 1.0, includes_high=True), unset="the whole frame interval",
        flag=Flag(
            "--exposure", unit="frame intervals", per="fps", range=Range(0.0, 1.0, includes_high=True), default=1.0, metavar="F",
            help="camera exposure, as a fraction of the frame interval",
        ),
    )  # fmt: skip
    width: int = setting(640, "pixels", "sensor width", Range(64.0, 4096.0, True, True))
    height: int = setting(480, "pixels", "sensor height", Range(48.0, 4096.0, True, True))
    noise_dn: float = setting(2.0, "DN", "sensor read noise, in digital numbers", SENSOR_LEVELS, flag=Flag("--noise-dn", group=FILM))
    dark_dn: float = setting(8.0, "DN", "the sensor's dark level", SENSOR_LEVELS)
    led_peak_dn: float = setting(900.0, "DN", "the LED's peak before the sensor saturates", Range(0.0, SENSOR_LEVELS.high, includes_high=True))
    display_black_dn: float = setting(6.0, "DN", "how bright the display's black films", SENSOR_LEVELS)
    display_white_dn: float = setting(
        190.0, "DN", "how bright the display's white films: lower for a dim sphere",
        Range(0.0, SENSOR_LEVELS.high, includes_high=True),
        flag=Flag("--display-white-dn", group=FILM),
    )  # fmt: skip
    subsamples: int = setting(8, "", "instants of each exposure averaged (motion blur)", Range(1.0, 64.0, True, True))
    impairments: FilmImpairments = field(default_factory=FilmImpairments)
    readout_s: float = setting(
        0.0, "seconds", "rolling shutter: row y of H starts exposing y/H of this after row 0, at most a frame interval",
        Range(0.0, 1.0, True, True), flag=Flag("--readout-ms", unit="ms", factor=1e3, metavar="R"),
    )  # fmt: skip
    frame_jitter_s: float = setting(
        0.0, "seconds", "start each exposure up to half this before or after its nominal time, drawn by the seed, as "
        "phones do; needs an mp4 or mov, which stamps each frame", Range(0.0, 1.0, True, True),
        flag=Flag("--frame-jitter-ms", unit="ms", factor=1e3, metavar="J", group=FILM),
    )  # fmt: skip
    container: str = setting("avi", "", "the film's file", choices=CONTAINERS, flag=Flag("--container", group=FILM))
    codec: str | None = setting(
        None, "", "the film's codec", choices=CODECS, unset="mjpeg in an avi, h264 in an mp4 or mov",
        flag=Flag("--codec", group=FILM),
    )  # fmt: skip

    def __post_init__(self) -> None:
        check(self, ConfigError, "camera.")
        if self.exposure_s is not None and not self.exposure_s <= 1.0 / self.fps:
            raise ConfigError(
                f"camera exposure must be positive and at most one frame interval ({1e3 / self.fps:.3f} ms), "
                f"got {self.exposure_s * 1e3:.3f} ms"
            )
        self._check_timing()
        check_film_format(*self.film, stamped=self.frame_jitter_s > 0.0)

    def _check_timing(self) -> None:
        """A readout within a frame interval (a sensor reads one frame's rows before the next's), and
        a jitter that never starts an exposure before the one before it is read out."""
        interval_ms = 1e3 / self.fps
        if self.readout_s > 1.0 / self.fps:
            raise ConfigError(
                f"camera readout must be 0 (global shutter) up to one frame interval ({interval_ms:.3f} ms), "
                f"got {self.readout_s * 1e3:g} ms"
            )
        busy = max(self.exposure, self.readout_s)
        if self.frame_jitter_s > 0.0 and self.frame_jitter_s > 1.0 / self.fps - busy:
            raise ConfigError(
                f"a frame-timing jitter of {self.frame_jitter_s * 1e3:g} ms would start exposures before the one "
                f"before has been exposed and read out ({busy * 1e3:.3f} ms of a {interval_ms:.3f} ms interval): "
                f"give a jitter of at most {(1.0 / self.fps - busy) * 1e3:.3f} ms, or a shorter exposure"
            )

    @property
    def film(self) -> tuple[str, str]:
        """The film's (container, codec) (`rig.film_file`)."""
        return self.container, self.codec or default_codec(self.container)

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
        import numpy as np  # here, not above: the settings are read without numpy

        return (np.arange(self.subsamples) + 0.5) / self.subsamples * self.exposure

    def row_delays(self, rows: np.ndarray) -> np.ndarray:
        """When each of `rows` (row indices, 0 at the top) starts exposing, after row 0 (s)."""
        import numpy as np

        return np.asarray(rows, dtype=np.float64) / self.height * self.readout_s
