"""The simulated tracker (`SimTracker`), a twin of `rig.devices.protocols.TrackerSource`.

The simulated sensor rides on the pendulum bob. It measures at a fixed rate on its own clock and
sends each measurement over a serial/USB-like transport:

* t_sensor = t_start + phase_s + k / rate_hz, for every k with t_sensor < t_end;
* the position gets independent Gaussian noise, position_noise_m per axis;
* the orientation gets a random small rotation in the sensor (body) frame: a rotation vector with
  independent Gaussian components of orientation_noise_deg, applied as q_true * q_noise;
* t_arrival = t_sensor + transport_delay_s + jitter, the jitter exponentially distributed with
  mean jitter_s (a transport is sometimes late, never early);
* the transport never reorders: a sample that would overtake its predecessor arrives with it,
  so t_arrival is non-decreasing;
* each sample is lost with probability `dropout`, independently.

All randomness comes from numpy's default_rng(seed), drawn for every sample in a fixed order, so a
seed fixes the whole run and changing the dropout rate does not change the noise of the samples
that are kept. The samples are worked out once, when the tracker connects, and handed out as the
rig clock passes their arrival times.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from predictors import PoseSample
from rig.clock import Clock
from rig.devices.protocols import Fault
from rig.errors import ConfigError, RigError
from rig.sim.pendulum import Pendulum


@dataclass(frozen=True)
class TrackerConfig:
    """Rate, noise and transport of a simulated tracker. Times in seconds, noise as std-devs."""

    rate_hz: float = 120.0
    position_noise_m: float = 0.0002
    orientation_noise_deg: float = 0.05
    transport_delay_s: float = 0.004
    jitter_s: float = 0.0005
    dropout: float = 0.0
    phase_s: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.rate_hz) and self.rate_hz > 0.0):
            raise ConfigError(
                f"tracker.rate_hz must be a positive finite rate in Hz, got {self.rate_hz!r}"
            )
        for name in ("position_noise_m", "orientation_noise_deg", "transport_delay_s", "jitter_s"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ConfigError(f"tracker.{name} must be a finite number >= 0, got {value!r}")
        if not (0.0 <= self.dropout < 1.0):
            raise ConfigError(f"tracker.dropout must be a probability in [0, 1), got {self.dropout!r}")
        if not (0.0 <= self.phase_s < 1.0 / self.rate_hz):
            raise ConfigError(
                f"tracker.phase_s must be in [0, 1 / rate_hz) = [0, {1.0 / self.rate_hz!r}) s, "
                f"got {self.phase_s!r}"
            )


def simulate_tracker(
    pendulum: Pendulum, config: TrackerConfig, t_start: float, t_end: float, seed: int
) -> list[PoseSample]:
    """The samples a tracker on `pendulum` delivers for sensor times in [t_start, t_end).

    Sorted by t_arrival (which, as the transport keeps order, is also t_sensor order).
    """
    if not (math.isfinite(t_start) and math.isfinite(t_end) and t_end > t_start):
        raise ConfigError(f"simulate_tracker needs t_end > t_start, got t_start={t_start!r}, t_end={t_end!r}")
    if t_start < pendulum.t_start or t_end > pendulum.t_end:
        raise ConfigError(
            f"the tracker window [{t_start!r}, {t_end!r}] s is not inside the pendulum's "
            f"[{pendulum.t_start!r}, {pendulum.t_end!r}] s; simulate the pendulum over a longer window"
        )
    count = math.ceil((t_end - t_start - config.phase_s) * config.rate_hz) + 1
    t_sensor = t_start + config.phase_s + np.arange(count) / config.rate_hz
    t_sensor = t_sensor[t_sensor < t_end]
    n = t_sensor.size

    rng = np.random.default_rng(seed)
    position_noise = config.position_noise_m * rng.standard_normal((n, 3))
    rotation_noise = math.radians(config.orientation_noise_deg) * rng.standard_normal((n, 3))
    jitter = config.jitter_s * rng.standard_exponential(n)
    kept = rng.random(n) >= config.dropout

    positions, orientations = pendulum.sensor_pose(t_sensor)
    positions = positions + position_noise
    from scipy.spatial.transform import Rotation  # here: scipy.spatial takes longer to import than most runs take to use it

    measured = Rotation.from_quat(orientations, scalar_first=True) * Rotation.from_rotvec(rotation_noise)
    orientations = measured.as_quat(scalar_first=True)
    orientations /= np.linalg.norm(orientations, axis=1, keepdims=True)

    t_sensor, positions, orientations = t_sensor[kept], positions[kept], orientations[kept]
    t_arrival = np.maximum.accumulate(t_sensor + config.transport_delay_s + jitter[kept])
    return [
        PoseSample(float(ts), float(ta), p, q)
        for ts, ta, p, q in zip(t_sensor, t_arrival, positions, orientations)
    ]


class SimTracker:
    """The simulated tracker of a run: samples for sensor times in [t_start, t_end), handed out
    as the clock passes their arrival."""

    def __init__(self, pendulum: Pendulum, config: TrackerConfig, t_start: float, t_end: float, seed: int) -> None:
        self.pendulum = pendulum
        self.config = config
        self.t_start = t_start
        self.t_end = t_end
        self.seed = seed
        self._clock: Clock | None = None
        self._samples: list[PoseSample] = []
        self._next = 0

    def connect(self, clock: Clock) -> None:
        self._samples = simulate_tracker(self.pendulum, self.config, self.t_start, self.t_end, self.seed)
        if not self._samples:
            raise RigError("the tracker produced no samples; check its rate and dropout settings")
        self._clock = clock
        self._next = 0

    def poll(self) -> list[PoseSample]:
        """The samples that have arrived by now and were not handed out before."""
        now = self._connected().now()
        first = self._next
        while self._next < len(self._samples) and self._samples[self._next].t_arrival <= now:
            self._next += 1
        return self._samples[first : self._next]

    def wait(self, timeout_s: float) -> list[PoseSample]:
        """Move the clock on to the next arrival, if it comes within `timeout_s`; then poll."""
        clock = self._connected()
        if self._next < len(self._samples):
            arrival = self._samples[self._next].t_arrival
            if arrival <= clock.now() + timeout_s:
                clock.wait_until(arrival)
        return self.poll()

    def fault(self) -> Fault | None:
        """None: the simulated transport never stops."""
        return None

    def report(self) -> dict[str, Any]:
        return {"tracker": "sim", "samples": len(self._samples), "delivered": self._next}

    def close(self) -> None:
        self._clock = None

    def _connected(self) -> Clock:
        if self._clock is None:
            raise RigError("the simulated tracker is not connected; call connect(clock) first")
        return self._clock
