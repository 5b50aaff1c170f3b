"""Shared by the board estimator tests (and by tests/rig/board, for `rig board latency`): a synthetic
board recording of a pendulum and a late display, with the truth known."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import pytest


@dataclass(frozen=True)
class SyntheticRecording:
    """What a board records of a pendulum and a late display, computed exactly (board seconds):
    encoder edges (time, count after, step) and photodiode passages (centroid time, duration)."""

    edge_times: np.ndarray
    counts: np.ndarray
    steps: np.ndarray
    centroids: np.ndarray
    durations: np.ndarray
    period: float


def synthesise_recording(
    latency: float,
    *,
    amplitude: float = 0.3,
    period: float = 1.25,
    decay: float = 0.0,
    photodiode: float = 0.02,
    width: float = 0.02,
    counts_per_rev: int = 2400,
    duration: float = 8.0,
    noise: float = 0.003,
    fall: float = 0.25,
    rise: float = 0.6,
    seed: int = 0,
) -> SyntheticRecording:
    """Angles in radians. The display shows angle(t - latency); the photodiode sees a Gaussian
    spot of `width` centred at `photodiode`, sampled every 104 us with `noise` (relative to the
    spot's brightness); passages are windows above `fall` that reach `rise`, timed by their
    centroid as the firmware does."""

    def angle(t: np.ndarray) -> np.ndarray:
        envelope = np.exp(-t / decay) if decay else 1.0
        return amplitude * envelope * np.cos(2 * np.pi * t / period)

    grid = np.arange(0.0, duration, 20e-6)
    position = angle(grid) * counts_per_rev / (2 * np.pi)
    count = np.floor(position + 0.5)
    changed = np.flatnonzero(np.diff(count)) + 1
    boundary = 0.5 * (count[changed] + count[changed - 1])
    fraction = (boundary - position[changed - 1]) / (position[changed] - position[changed - 1])
    edge_times = grid[changed - 1] + fraction * 20e-6

    samples = np.arange(0.0, duration, 104e-6)
    rng = np.random.default_rng(seed)
    signal = np.exp(-0.5 * ((angle(samples - latency) - photodiode) / width) ** 2) + noise * rng.standard_normal(samples.size)
    above = signal > fall
    starts = np.flatnonzero(above[1:] & ~above[:-1]) + 1
    ends = np.flatnonzero(~above[1:] & above[:-1]) + 1
    centroids, durations = [], []
    for start in starts:
        later = ends[ends > start]
        if later.size and signal[start : later[0]].max() >= rise:
            excess = signal[start : later[0]] - fall
            centroids.append(np.sum(excess * samples[start : later[0]]) / np.sum(excess))
            durations.append(samples[later[0] - 1] - samples[start])
    return SyntheticRecording(
        edge_times=edge_times,
        counts=count[changed],
        steps=np.sign(count[changed] - count[changed - 1]),
        centroids=np.array(centroids),
        durations=np.array(durations),
        period=period,
    )


@pytest.fixture(scope="session")
def synthetic_recording() -> Callable[..., SyntheticRecording]:
    """synthetic_recording(latency, **options): see synthesise_recording."""
    return synthesise_recording
