"""A simulated display's settings, each declared on its field: what the command line's options are
made from, without the simulation's numerical libraries (`rig.sim.display` simulates it)."""

from __future__ import annotations

from dataclasses import dataclass

from declared import FRACTION, Flag, Range, check, setting
from rig.errors import ConfigError

COMMON_REFRESH_HZ = (60.0, 90.0, 120.0, 144.0)


@dataclass(frozen=True)
class DisplayConfig:
    refresh_hz: float = setting(
        60.0, "Hz", "display refresh rate: headsets and monitors refresh at 60 to 240 Hz, none at 1000",
        Range(1.0, 1000.0, True, True), flag="--display-hz",
    )  # fmt: skip
    width: int = setting(320, "pixels", "display width", Range(16.0, 4096.0, True, True))
    height: int = setting(240, "pixels", "display height", Range(16.0, 4096.0, True, True))
    scanout_fraction: float = setting(1.0, "", "share of a refresh period that scan-out takes", Range(0.0, 1.0, includes_high=True))
    t0: float = setting(0.0, "seconds", "the rig clock's time of the first refresh before its phase", Range(-3600.0, 3600.0, True, True))
    phase: float = setting(
        0.0, "", "when the display's refreshes start against the camera's frames, as a fraction of a refresh", FRACTION,
        flag=Flag("--display-phase", metavar="P"),
    )  # fmt: skip

    def __post_init__(self) -> None:
        check(self, ConfigError, "display.")

    @property
    def origin(self) -> float:
        """The vertical blank of refresh 0 (s)."""
        return self.t0 + self.phase / self.refresh_hz
