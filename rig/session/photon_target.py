"""The instant each display frame's pose is predicted for, declared for the command line without the
session's libraries (`rig.session.timing` holds the renderer's timing policies)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from declared import Range, check, setting
from rig.errors import ConfigError

if TYPE_CHECKING:
    from rig.devices.protocols import Display

PHOTON_TARGETS = ("photons", "scanout")


@dataclass(frozen=True)
class PhotonTarget:
    """The instant a display frame's pose is predicted for, at the tracked object's display row.

    mode "scanout": when the frame's scan-out reaches the row; "photons": the middle of the interval
    the row then emits the frame, scan-out plus half the persistence. `persistence` is the share of
    a refresh period a row emits each frame: 1 for a sample-and-hold display (the simulated one),
    less for a low-persistence (strobed) panel.
    """

    mode: str = setting(
        "photons", "", "the instant each frame's pose is predicted for, at the sphere's row: 'photons' the middle of the "
        "interval the row emits it (scan-out plus half the persistence), 'scanout' when scan-out reaches the row",
        choices=PHOTON_TARGETS,
    )  # fmt: skip
    persistence: float = setting(
        1.0, "", "share of a refresh each display row emits a frame: 1 for sample-and-hold (the simulated display), "
        "less for a low-persistence panel", Range(0.0, 1.0, includes_high=True),
    )  # fmt: skip

    def __post_init__(self) -> None:
        check(self, ConfigError)

    def time(self, display: Display, k: int, row_fraction: float) -> float:
        """The instant refresh k's pose is predicted for, for an object at `row_fraction`."""
        t = display.photon_time(k, row_fraction)
        if self.mode == "photons":
            t += 0.5 * self.persistence / display.refresh_hz
        return t

DEFAULT_SERVER_MS = 2.0
"""Modelled server cost per composed image of a renderer that composes at every refresh: a GPU's
point warp of a display-sized image, well inside a refresh. Software OpenGL takes longer, which a
run with measured costs shows as missed refreshes."""
