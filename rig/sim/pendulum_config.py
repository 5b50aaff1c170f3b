"""A simulated pendulum's settings, each declared on its field: what the command line's options are
made from, without the simulation's numerical libraries (`rig.sim.pendulum` simulates it)."""

from __future__ import annotations

import math
from dataclasses import dataclass

from declared import Flag, Range, check, setting
from rig.errors import ConfigError

MAX_AMPLITUDE_DEG = 45.0


@dataclass(frozen=True)
class PendulumConfig:
    """A pendulum, given by its small-angle period or its length (exactly one of the two).

    amplitude_deg is the angle the pendulum is released from, at rest. phase_deg says where in
    the swing the simulation starts: the release happens phase_deg / 360 of a period (the exact
    period at that amplitude) before the start time, so 0 starts at the release and 90 starts near
    the first downward zero crossing. release_s instead holds the pendulum at rest at +amplitude
    until that time (s, on the simulation's clock) and releases it then; phase_deg must be 0 with
    it. quality is the Q factor of the viscous damping; math.inf means undamped. Each setting is
    declared on its field (`declared.setting`).
    """

    period_s: float | None = setting(
        1.0, "seconds", "pendulum period (small-angle): a lab's pendulum swings once in a fraction of a second (a 1 cm "
        "arm) to tens of seconds (a 100 m one); a spec may give length_m instead", Range(0.2, 20.0, True, True), flag="--period-s",
    )
    length_m: float | None = setting(None, "metres", "pendulum length, instead of the period", Range(0.01, 100.0, True, True), unset="from the period")
    amplitude_deg: float = setting(
        20.0, "degrees", "swing amplitude, the angle it is released from", Range(0.0, MAX_AMPLITUDE_DEG, includes_high=True),
        flag="--amplitude-deg",
    )  # fmt: skip
    quality: float = setting(
        200.0, "", "pendulum quality factor Q; inf for no damping", Range(0.0, math.inf, includes_high=True), flag="--quality"
    )
    g: float = setting(9.80665, "m/s^2", "gravity (Earth's; up to ten times it)", Range(0.0, 100.0, includes_high=True))
    phase_deg: float = setting(
        0.0, "degrees", "where in the swing the simulation starts (0: at the release)", Range(0.0, 360.0, includes_low=True)
    )
    pivot: tuple[float, float, float] = setting((0.0, 0.0, 0.0), "metres", "the pivot's position, within 100 m of the origin", Range(-100.0, 100.0, True, True))
    release_s: float | None = setting(
        None, "seconds", "hold the pendulum at rest at its amplitude and release it S seconds into the film (at least "
        "one swing before the end)", Range(-3600.0, 3600.0, True, True), unset="swinging from the start",
        flag=Flag("--release-s", range=Range(0.0, 3600.0, True, True), metavar="S", group="lab"),
    )  # fmt: skip

    def __post_init__(self) -> None:
        check(self, ConfigError, "pendulum.")
        if (self.period_s is None) == (self.length_m is None):
            raise ConfigError(
                "PendulumConfig needs exactly one of period_s and length_m; "
                f"got period_s={self.period_s!r}, length_m={self.length_m!r}"
            )
        if self.release_s is not None and self.phase_deg != 0.0:
            raise ConfigError(
                "pendulum.release_s and phase_deg exclude each other: a held pendulum starts "
                f"from rest at its release, so leave phase_deg at 0 (got {self.phase_deg!r})"
            )
        if len(self.pivot) != 3:
            raise ConfigError(f"pendulum.pivot must be three finite coordinates in metres, got {self.pivot!r}")

    @property
    def resolved_length_m(self) -> float:
        """The length in metres, from length_m or from the small-angle period."""
        if self.length_m is not None:
            return float(self.length_m)
        assert self.period_s is not None
        return self.g * (self.period_s / (2.0 * math.pi)) ** 2

    @property
    def small_angle_period_s(self) -> float:
        """2 pi sqrt(L / g): the period of an infinitesimal, undamped swing."""
        return 2.0 * math.pi * math.sqrt(self.resolved_length_m / self.g)
