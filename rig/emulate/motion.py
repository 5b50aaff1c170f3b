"""What an emulated tracker measures: the simulated pendulum, or a recorded trace played in a loop.

Poses are worked out a block at a time (numpy over many samples), so the sending loop only looks
them up.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from predictors import quaternion, read_trace
from rig.sim.pendulum import Pendulum, PendulumConfig

BLOCK = 1000


class Motion:
    """Poses at the sample times k / rate_hz, k = 0, 1, ...: `pose(k)` gives (position, orientation,
    angular rate), as tuples of floats."""

    def __init__(self, rate_hz: float, duration_s: float, trace: Path | None = None) -> None:
        self.rate_hz = rate_hz
        self.source = str(trace) if trace else "simulated pendulum"
        if trace is None:
            # Poses come a block at a time: the window covers the whole block of the last sample.
            blocks = math.ceil((duration_s * rate_hz + 1) / BLOCK)
            pendulum = Pendulum(PendulumConfig(), t_end=max(duration_s + 2.0, (blocks * BLOCK + 1) / rate_hz))
            self._pose_at = pendulum.sensor_pose
        else:
            recorded = read_trace(trace)
            start, span = float(recorded.truth_t[0]), max(recorded.duration, 1.0 / rate_hz)
            self._pose_at = lambda t: recorded.truth_at(start + np.mod(t, span))
        self._block = -1
        self._poses: list[tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]] = []

    def pose(self, k: int) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
        block = k // BLOCK
        if block != self._block:
            self._fill(block)
        return self._poses[k - block * BLOCK]

    def _fill(self, block: int) -> None:
        t = (block * BLOCK + np.arange(BLOCK + 1)) / self.rate_hz
        positions, orientations = self._pose_at(t)
        orientations = quaternion.normalise(orientations)
        turn = quaternion.multiply(quaternion.conjugate(orientations[:-1]), orientations[1:])
        rates = quaternion.to_rotation_vector(turn) * self.rate_hz
        self._poses = [
            (tuple(p), tuple(q), tuple(w)) for p, q, w in zip(positions[:-1].tolist(), orientations[:-1].tolist(), rates.tolist())
        ]
        self._block = block
