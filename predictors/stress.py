"""Synthetic stress streams: the motions and tracker faults a default predictor must survive.

Every stream is a trace whose truth is the clean motion at 1000 Hz and whose samples are what a
tracker of some kind would deliver from it: its rate (30 to 1000 Hz), irregular sample times, white
noise (`Trace.with_noise`) or coloured noise, repeated samples (a tracker that did not update), and
motion that starts and stops at once. `stress_streams` builds the named set that `rig bench predictors --stress` runs;
the pieces compose for other sets:

    truth = head_motion_truth(20.0, seed=1)
    stream = sampled(truth, 90.0, jitter=0.3, seed=1).with_noise(0.0005, math.radians(0.1), seed=1)

A predictor developed on two recordings is judged on others: these streams are where a design
choice is checked before it is ever run on a recording.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from predictors import quaternion
from predictors.errors import PredictorError
from predictors.synthetic import head_motion
from predictors.trace import Trace

TRUTH_RATE_HZ = 1000.0


def head_motion_truth(duration_s: float, seed: int) -> Trace:
    """`predictors.synthetic.head_motion` at `TRUTH_RATE_HZ`, to sample streams from."""
    return head_motion(duration_s, TRUTH_RATE_HZ, seed)


def sudden_stops(duration_s: float, seed: int, name: str = "sudden-stops") -> Trace:
    """Rest and motion at constant velocity, switching at once (no ramp): rests of 0.2 to 1.5 s,
    turns at 30 to 250 deg/s about a random axis near vertical or horizontal for 0.1 to 0.8 s,
    and the head's position moving at up to 0.5 m/s during each turn. The worst case for a
    predictor that has learnt to trust its velocity, and for one that has learnt not to."""
    if not (math.isfinite(duration_s) and duration_s > 0.0):
        raise PredictorError(f"sudden_stops needs a positive duration, got {duration_s!r} s")
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration_s * TRUTH_RATE_HZ) + 1) / TRUTH_RATE_HZ
    angular_velocity = np.zeros((t.size, 3))
    velocity = np.zeros((t.size, 3))
    start = rng.uniform(0.2, 1.5)
    while start < t[-1]:
        length = rng.uniform(0.1, 0.8)
        axis = rng.normal(size=3) * (0.3, 1.0, 0.3) if rng.random() < 0.7 else rng.normal(size=3) * (1.0, 0.3, 0.3)
        moving = (t >= start) & (t < start + length)
        angular_velocity[moving] = math.radians(rng.uniform(30.0, 250.0)) * axis / np.linalg.norm(axis)
        velocity[moving] = rng.uniform(0.0, 0.5) * _unit(rng.normal(size=3))
        start += length + rng.uniform(0.2, 1.5)
    step = 1.0 / TRUTH_RATE_HZ
    turns = quaternion.from_rotation_vector(angular_velocity[:-1] * step)
    orientation = np.empty((t.size, 4))
    orientation[0] = (1.0, 0.0, 0.0, 0.0)
    for k in range(1, t.size):
        orientation[k] = quaternion.multiply(turns[k - 1], orientation[k - 1])
    position = np.array([0.0, 1.6, 0.0]) + np.vstack([np.zeros(3), np.cumsum(velocity[:-1] * step, axis=0)])
    return Trace.from_samples(name, t, position, quaternion.normalise(orientation))


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def sampled(truth: Trace, rate_hz: float, jitter: float = 0.0, seed: int = 0, name: str | None = None) -> Trace:
    """A tracker sampling `truth` at `rate_hz`, each sample time moved by up to `jitter` (a
    fraction of the interval, uniform) and stamped with its true time, scored against `truth`."""
    if not (math.isfinite(rate_hz) and rate_hz > 0.0 and 0.0 <= jitter < 0.5):
        raise PredictorError(f"sampling needs a positive rate and a jitter in [0, 0.5), got {rate_hz!r} Hz, {jitter!r}")
    rng = np.random.default_rng(seed)
    start, end = truth.truth_t[0], truth.truth_t[-1]
    t = start + np.arange(int(math.floor((end - start) * rate_hz)) + 1) / rate_hz
    t = np.clip(t + jitter / rate_hz * rng.uniform(-1.0, 1.0, t.size), start, end)
    position, orientation = truth.truth_at(t)
    stream = truth.with_samples(t, t.copy(), position, orientation)
    return replace(stream, name=name or f"{truth.name}-{rate_hz:g}Hz")


def with_coloured_noise(
    trace: Trace, position_std_m: float, orientation_std_rad: float, correlation: float, seed: int
) -> Trace:
    """Noise correlated from one sample to the next (AR(1) with coefficient `correlation`, in
    (-1, 1), of the given standard deviation): positive for a slowly wandering error (optical
    drift), negative for one that alternates from frame to frame."""
    if not -1.0 < correlation < 1.0:
        raise PredictorError(f"a noise correlation must be in (-1, 1), got {correlation!r}")
    rng = np.random.default_rng(seed)
    n = len(trace)
    white = rng.standard_normal((n, 6)) * math.sqrt(1.0 - correlation * correlation)
    noise = np.empty((n, 6))
    noise[0] = rng.standard_normal(6)
    for k in range(1, n):
        noise[k] = correlation * noise[k - 1] + white[k]
    position = trace.position + position_std_m * noise[:, :3]
    turn = quaternion.from_rotation_vector(orientation_std_rad * noise[:, 3:])
    orientation = quaternion.normalise(quaternion.multiply(trace.orientation, turn))
    return trace.with_samples(trace.t, trace.t_arrival, position, orientation)


def with_repeats(trace: Trace, fraction: float, seed: int) -> Trace:
    """A tracker that sometimes did not update: a `fraction` of the samples repeat the pose of the
    sample before, under their own time."""
    if not 0.0 <= fraction < 1.0:
        raise PredictorError(f"a repeated fraction must be in [0, 1), got {fraction!r}")
    rng = np.random.default_rng(seed)
    source = np.arange(len(trace))
    repeat = rng.random(len(trace)) < fraction
    repeat[0] = False
    for k in np.flatnonzero(repeat):
        source[k] = source[k - 1]
    return trace.with_samples(trace.t, trace.t_arrival, trace.position[source], trace.orientation[source])


def stress_streams(duration_s: float = 20.0, seed: int = 0) -> list[Trace]:
    """The named stress set: head motion at 30 to 1000 Hz, clean to noisy, with jittered times,
    repeated samples and coloured noise, and sudden stops at 60 and 500 Hz."""
    head = head_motion_truth(duration_s, seed)
    stops = sudden_stops(duration_s, seed + 1)
    degree = math.radians(1.0)

    def named(trace: Trace, name: str) -> Trace:
        return replace(trace, name=name)

    return [
        named(sampled(head, 30.0, seed=seed).with_noise(0.0002, 0.02 * degree, seed), "head-30Hz"),
        named(sampled(head, 60.0, seed=seed), "head-60Hz-clean"),
        named(sampled(head, 120.0, seed=seed).with_noise(0.0005, 0.1 * degree, seed), "head-120Hz"),
        named(sampled(head, 1000.0, seed=seed).with_noise(0.001, 0.3 * degree, seed), "head-1000Hz-noisy"),
        named(
            with_repeats(sampled(head, 60.0, jitter=0.3, seed=seed).with_noise(0.0, 0.05 * degree, seed), 0.05, seed),
            "head-60Hz-jitter-repeats",
        ),
        named(with_coloured_noise(sampled(head, 90.0, seed=seed), 0.001, 0.2 * degree, -0.6, seed), "head-90Hz-alternating"),
        named(with_coloured_noise(sampled(head, 250.0, seed=seed), 0.001, 0.1 * degree, 0.9, seed), "head-250Hz-drifting"),
        named(sampled(stops, 60.0, seed=seed).with_noise(0.0002, 0.03 * degree, seed), "stops-60Hz"),
        named(sampled(stops, 500.0, seed=seed).with_noise(0.0005, 0.1 * degree, seed), "stops-500Hz"),
    ]
