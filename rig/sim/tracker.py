"""The simulated tracker: what a tracker on a moving body measures and when each sample reaches the
host, worked out in one place for the in-process twin of a simulated run (`SimTracker`, a
`rig.devices.protocols.TrackerSource`) and for the emulated tracker of `rig emulate-tracker`
(`rig.emulate`, which encodes the same samples as a device's bytes and sends them in real time).

The sensor rides on a `Motion` (the pendulum's bob, or a recorded trace). It measures at a fixed
rate on its own clock and sends each measurement over a serial/USB-like transport:

* t_sensor = t_start + phase_s + k / rate_hz, for every k with t_sensor < t_end;
* the position gets independent Gaussian noise, position_noise_m per axis;
* the orientation gets a random small rotation in the sensor (body) frame: a rotation vector with
  independent Gaussian components of orientation_noise_deg, applied as q_true * q_noise;
* t_arrival = t_sensor + transport_delay_s + jitter, the jitter exponentially distributed with
  mean jitter_s (a transport is sometimes late, never early);
* the transport never reorders: a sample that would overtake its predecessor arrives with it,
  so t_arrival is non-decreasing;
* each sample is lost with probability `dropout`, independently;
* then the faults in time of a `FaultPlan` (`rig.sim.tracker_faults.delivered`: bursts, stalls,
  disconnects); the faults in bytes are the emulator's, which sends bytes.

All randomness comes from numpy's default_rng(seed), drawn for every sample in a fixed order, so a
seed fixes the whole run and changing the dropout rate does not change the noise of the samples
that are kept. `SimTracker` works the samples out when it connects and hands them out as the rig
clock passes their arrival times.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from declared import check
from predictors import PoseSample
from rig.clock import Clock
from rig.devices.protocols import Fault
from rig.errors import ConfigError, RigError
from rig.sim.tracker_faults import FaultPlan, delivered
from rig.sim.tracker_config import TrackerConfig

NO_FAULTS = FaultPlan()


class Motion(Protocol):
    """What the sensor rides on over [t_start, t_end] (`rig.sim.pendulum.Pendulum`, a trace)."""

    t_start: float
    t_end: float

    def sensor_pose(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Positions (N, 3) and unit (w, x, y, z) orientations (N, 4) at the times `t` (N,)."""


@dataclass(frozen=True)
class TrackerSamples:
    """Every sample measured in a window, in sensor-time order, as arrays: its number k on the
    sensor's grid, sensor time, when it reaches the host (for a lost one, when it would have), the
    measured position (N, 3) and orientation (N, 4), and whether it was lost."""

    seq: np.ndarray
    t_sensor: np.ndarray
    t_arrival: np.ndarray
    positions: np.ndarray
    orientations: np.ndarray
    lost: np.ndarray

    def pose_samples(self) -> list[PoseSample]:
        """The samples that reach the host, as a tracker source hands them on."""
        kept = ~self.lost
        return [
            PoseSample(float(ts), float(ta), p, q)
            for ts, ta, p, q in zip(self.t_sensor[kept], self.t_arrival[kept], self.positions[kept], self.orientations[kept])
        ]


def measure(motion: Motion, config: TrackerConfig, t_start: float, t_end: float, seed: int, faults: FaultPlan = NO_FAULTS) -> TrackerSamples:
    """What a tracker on `motion` measures for sensor times in [t_start, t_end), and when each
    sample reaches the host (see the module docstring)."""
    if not (math.isfinite(t_start) and math.isfinite(t_end) and t_end > t_start):
        raise ConfigError(f"a simulated tracker needs t_end > t_start, got t_start={t_start!r}, t_end={t_end!r}")
    if t_start < motion.t_start or t_end > motion.t_end:
        raise ConfigError(
            f"the tracker window [{t_start!r}, {t_end!r}] s is not inside the motion's "
            f"[{motion.t_start!r}, {motion.t_end!r}] s; simulate the pendulum over a longer window"
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

    positions, orientations = motion.sensor_pose(t_sensor)
    positions = positions + position_noise
    from scipy.spatial.transform import Rotation  # here: scipy.spatial takes longer to import than most runs take to use it

    measured = Rotation.from_quat(orientations, scalar_first=True) * Rotation.from_rotvec(rotation_noise)
    orientations = measured.as_quat(scalar_first=True)
    orientations /= np.linalg.norm(orientations, axis=1, keepdims=True)

    t_arrival = t_sensor + config.transport_delay_s + jitter
    t_arrival[kept] = np.maximum.accumulate(t_sensor[kept] + config.transport_delay_s + jitter[kept])
    t_arrival, lost = delivered(faults, t_arrival, ~kept)
    return TrackerSamples(np.arange(n), t_sensor, t_arrival, positions, orientations, lost)


class SimTracker:
    """The simulated tracker of a run: samples for sensor times in [t_start, t_end), handed out as
    the clock passes their arrival. `faults` may only be faults in time: there are no bytes here."""

    def __init__(
        self, motion: Motion, config: TrackerConfig, t_start: float, t_end: float, seed: int, faults: FaultPlan = NO_FAULTS
    ) -> None:
        if faults.damages_bytes:
            raise ConfigError("a simulated tracker carries no bytes to damage: corrupt, drop and garbage are serial faults")
        self.motion = motion
        self.config = config
        self.t_start = t_start
        self.t_end = t_end
        self.seed = seed
        self.faults = faults
        self._clock: Clock | None = None
        self._samples: list[PoseSample] = []
        self._next = 0

    def connect(self, clock: Clock) -> None:
        self._samples = measure(self.motion, self.config, self.t_start, self.t_end, self.seed, self.faults).pose_samples()
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
