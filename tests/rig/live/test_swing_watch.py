"""The swing watch that ends a live run once the pendulum has stopped: a swing dying away below a
tenth of its first extent stops it, a steady one never does."""

from __future__ import annotations

import numpy as np

from predictors import PoseSample
from rig.devices.tap import TappedTracker
from rig.live.still import STILL_FRACTION, WINDOW_S, SwingWatch

RATE_HZ = 100.0
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def _swing(amplitude_m, seconds: float) -> list[PoseSample]:
    t = np.arange(0.0, seconds, 1.0 / RATE_HZ)
    x = amplitude_m(t) * np.sin(2.0 * np.pi * t)
    return [PoseSample(float(ti), float(ti), np.array([xi, 0.0, 0.0]), IDENTITY) for ti, xi in zip(t, x)]


def test_a_steady_swing_is_never_still() -> None:
    watch = SwingWatch()
    watch(_swing(lambda t: np.full_like(t, 0.2), 20.0))
    assert not watch.stopped


def test_a_swing_dying_away_is_still_once_below_a_tenth_of_its_first_extent() -> None:
    decay_s = 3.0
    samples = _swing(lambda t: 0.2 * np.exp(-t / decay_s), 20.0)
    watch = SwingWatch()
    for k in range(0, len(samples), 7):
        watch(samples[k : k + 7])
        if watch.stopped:
            break
    # The window that first falls below a tenth of the first one's extent ends it, no earlier.
    windows_needed = np.ceil(decay_s * np.log(1.0 / STILL_FRACTION) / WINDOW_S)
    assert watch.stopped
    assert windows_needed * WINDOW_S <= samples[k].t_sensor <= (windows_needed + 2) * WINDOW_S


class _Source:
    def __init__(self, samples: list[PoseSample]) -> None:
        self.samples = samples

    def poll(self) -> list[PoseSample]:
        taken, self.samples = self.samples, []
        return taken


def test_a_tapped_tracker_shows_every_sample_to_each_tap_and_hands_it_on() -> None:
    samples = _swing(lambda t: np.full_like(t, 0.1), 1.0)
    seen: list[PoseSample] = []
    tracker = TappedTracker(_Source(samples), seen.extend, seen.extend)
    assert tracker.poll() == samples and tracker.poll() == []
    assert seen == samples + samples
