"""A simulated tracker's settings, each declared on its field: what the command line's options are
made from, without the simulation's numerical libraries (`rig.sim.tracker` simulates it)."""

from __future__ import annotations

from dataclasses import dataclass

from declared import FRACTION, Flag, Range, check, setting
from rig.errors import ConfigError


@dataclass(frozen=True)
class TrackerConfig:
    """Rate, noise and transport of a simulated tracker, each declared on its field (`declared.setting`)."""

    rate_hz: float = setting(
        120.0, "Hz", "tracker sample rate: optical trackers sample at tens to hundreds of Hz, inertial ones up to a few kHz",
        Range(1.0, 5000.0, True, True), flag="--tracker-hz",
    )  # fmt: skip
    position_noise_m: float = setting(0.0002, "metres", "position noise, standard deviation per axis", Range(0.0, 0.1, True, True))
    orientation_noise_deg: float = setting(
        0.05, "degrees", "orientation noise, standard deviation of each rotation-vector component",
        Range(0.0, 10.0, True, True),
    )
    transport_delay_s: float = setting(
        0.004, "seconds", "fixed tracker-to-host delay, at most a second", Range(0.0, 1.0, True, True), flag=Flag("--transport-delay-ms", unit="ms", factor=1e3)
    )
    jitter_s: float = setting(0.0005, "seconds", "mean transport jitter, exponentially distributed", Range(0.0, 0.1, True, True))
    dropout: float = setting(0.0, "", "probability that a sample is lost", FRACTION)
    phase_s: float = setting(0.0, "seconds", "first sensor time after the start, less than one sample interval", Range(0.0, 1.0, True))

    def __post_init__(self) -> None:
        check(self, ConfigError, "tracker.")
        if not self.phase_s < 1.0 / self.rate_hz:
            raise ConfigError(
                f"tracker.phase_s must be in [0, 1 / rate_hz) = [0, {1.0 / self.rate_hz!r}) s, "
                f"got {self.phase_s!r}"
            )
