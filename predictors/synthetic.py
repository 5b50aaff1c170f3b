"""A synthetic head-motion generator: turns, stops and sway, like a person looking around.

The head looks at one place for a while (a fixation, 0.3 to 2 s, with slow drift), then turns to
the next one: yaw by 5 to 90 degrees and pitch by up to 30 degrees, each turn a minimum-jerk profile
of 0.25 to 0.8 s that starts from and ends at rest, so motion starts and stops suddenly. A turn's
peak angular speed, 1.875 times its angle over its duration, is capped at 290 deg/s (a turn too fast
is slowed down), so that with the sway on top, a few sines between 0.1 and 0.8 Hz and 1.5 degrees in
each axis, the head turns at up to about 300 deg/s.
Nearly all the energy of the angles is below 2 Hz.

Position follows: the head's centre sits 0.10 m above and 0.08 m in front of the neck pivot and
turns about it, and the pivot sways by a few centimetres below 0.5 Hz.

World frame: y up, -z forward (the head looks along its body's -z). Samples come at `rate_hz`,
noiseless (add noise with `Trace.with_noise`); the trace's truth is the same motion.
"""

from __future__ import annotations

import math

import numpy as np

from predictors import quaternion
from predictors.errors import PredictorError
from predictors.trace import Trace

TURN_SPEED_CAP_DEG_S = 290.0
_NECK_OFFSET_M = np.array([0.0, 0.10, -0.08])


def _minimum_jerk(u: np.ndarray) -> np.ndarray:
    """0 to 1 over u in [0, 1] with zero velocity and acceleration at both ends."""
    u = np.clip(u, 0.0, 1.0)
    return u**3 * (10.0 - 15.0 * u + 6.0 * u * u)


def _turns(t: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Yaw and pitch (rad) of fixations and minimum-jerk turns over times t."""
    yaw, pitch = np.zeros_like(t), np.zeros_like(t)
    start, target_yaw, target_pitch = float(t[0]) + rng.uniform(0.3, 2.0), 0.0, 0.0
    while start < t[-1]:
        duration = rng.uniform(0.25, 0.8)
        turn_yaw = math.radians(rng.uniform(5.0, 90.0)) * rng.choice([-1.0, 1.0])
        # Keep looking roughly ahead: turn back towards the middle when far out.
        if abs(target_yaw + turn_yaw) > math.radians(120.0):
            turn_yaw = -turn_yaw
        next_pitch = math.radians(rng.uniform(-30.0, 30.0))
        turn_pitch = next_pitch - target_pitch
        angle = math.hypot(turn_yaw, turn_pitch)
        duration = max(duration, 1.875 * math.degrees(angle) / TURN_SPEED_CAP_DEG_S)
        profile = _minimum_jerk((t - start) / duration)
        yaw += turn_yaw * profile
        pitch += turn_pitch * profile
        target_yaw, target_pitch = target_yaw + turn_yaw, next_pitch
        start += duration + rng.uniform(0.3, 2.0)
    return yaw, pitch


def _sway(t: np.ndarray, rng: np.random.Generator, amplitude: float, low_hz: float, high_hz: float) -> np.ndarray:
    """A sum of three sines with random frequencies in [low_hz, high_hz] and phases, RMS ~ amplitude."""
    frequencies = rng.uniform(low_hz, high_hz, 3)
    phases = rng.uniform(0.0, 2.0 * math.pi, 3)
    return amplitude * np.sqrt(2.0 / 3.0) * np.sin(2.0 * math.pi * frequencies * t[:, None] + phases).sum(axis=1)


def head_motion(duration_s: float = 60.0, rate_hz: float = 120.0, seed: int = 0, name: str = "synthetic-head") -> Trace:
    """A seeded synthetic head-motion trace (see the module docstring)."""
    if not (math.isfinite(duration_s) and duration_s > 0.0 and math.isfinite(rate_hz) and rate_hz > 0.0):
        raise PredictorError(f"head_motion needs a positive duration and rate, got {duration_s!r} s at {rate_hz!r} Hz")
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration_s * rate_hz) + 1) / rate_hz
    yaw, pitch = _turns(t, rng)
    sway = math.radians(1.5)
    yaw = yaw + _sway(t, rng, sway, 0.1, 0.8)
    pitch = pitch + _sway(t, rng, sway, 0.1, 0.8)
    roll = _sway(t, rng, sway, 0.1, 0.8)
    y_axis, x_axis, z_axis = np.eye(3)[1], np.eye(3)[0], np.eye(3)[2]
    orientation = quaternion.multiply(
        quaternion.multiply(quaternion.from_axis_angle(y_axis, yaw), quaternion.from_axis_angle(x_axis, pitch)),
        quaternion.from_axis_angle(z_axis, roll),
    )
    pivot = np.stack([_sway(t, rng, 0.02, 0.05, 0.5), _sway(t, rng, 0.005, 0.05, 0.5), _sway(t, rng, 0.02, 0.05, 0.5)], axis=1)
    position = pivot + np.array([0.0, 1.6, 0.0]) + quaternion.rotate(orientation, _NECK_OFFSET_M)
    return Trace.from_samples(name, t, position, orientation)
