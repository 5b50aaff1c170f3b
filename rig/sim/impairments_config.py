"""What a lab's camera does to its film, each setting declared on its field: what the command line's
options are made from, without the simulation's numerical libraries (`rig.sim.impairments` applies
them)."""

from __future__ import annotations

from dataclasses import dataclass

from declared import FRACTION, Flag, Range, check, setting
from rig.errors import ConfigError

Rect = tuple[int, int, int, int]
OCCLUDABLE = ("sphere", "led")
FILM = "film"
"""The group of the command line's options that these settings are."""
SENSOR_LEVELS = Range(0.0, 65535.0, True, True)
"""A level a sensor films, in digital numbers: zero up to a 16-bit sensor's full scale."""


@dataclass(frozen=True)
class FilmImpairments:
    """What a lab's camera does to its film, each setting declared on its field (`declared.setting`;
    the LED's half is the left one, unless mirrored); they act in the order of the fields."""

    blur_sigma_px: float = setting(0.0, "pixels", "defocus blur, Gaussian sigma", Range(0.0, 100.0, True, True), flag=Flag("--blur-px", group=FILM))
    dim_led: float = setting(
        1.0, "", "scale the LED's half of each frame by this, after the sensor saturates", Range(0.0, 1.0, includes_high=True),
        flag=Flag("--dim-led", metavar="F", group=FILM),
    )  # fmt: skip
    mirrored: bool = setting(
        False, "", "flip the film left to right: the LED on the right, the sphere on the left", flag=Flag("--mirrored", group=FILM)
    )
    bright_object_dn: float = setting(
        0.0, "DN", "a static lamp in view between and above the two halves, its peak (0: none)", SENSOR_LEVELS,
        flag=Flag("--bright-object-dn", group=FILM),
    )  # fmt: skip
    occluded: str | None = setting(
        None, "", "a bar hiding part of this blob's path", choices=OCCLUDABLE, unset="no bar", flag=Flag("--occluded", group=FILM)
    )
    missing_fraction: float = setting(
        0.0, "", "hide the sphere in this share of the frames, drawn by the seed", FRACTION,
        flag=Flag("--missing-fraction", metavar="F", group=FILM),
    )  # fmt: skip
    every_nth: int = setting(1, "", "film every N-th exposure only", Range(1.0, 1000.0, True, True), flag=Flag("--every-nth", metavar="N", group=FILM))
    first_frame: int = setting(
        0, "", "with --every-nth, the first exposure filmed, 0 to N - 1", Range(0.0, 999.0, True, True), flag=Flag("--first-frame", metavar="K", group=FILM)
    )

    def __post_init__(self) -> None:
        check(self, ConfigError, "camera.impairments.")
        if not self.first_frame < self.every_nth:
            raise ConfigError(
                f"a decimated film keeps every n-th frame (n >= 1) from frame 0 to n - 1, got every {self.every_nth} from {self.first_frame}"
            )

    def film_rect(self, rect: Rect, width: int) -> Rect:
        """Where a rectangle of the sensor's image lies in the film (mirrored, if the film is)."""
        x, y, w, h = rect
        return (width - x - w, y, w, h) if self.mirrored else rect
