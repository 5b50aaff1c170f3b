"""Cross-correlation with sub-sample peaks."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from analysis.estimators.xcorr import cosine_peak, pearson_at_lag, xcorr_latency


@given(st.floats(-0.5, 0.5), st.floats(0.05, 1.0), st.floats(0.1, 10.0))
def test_cosine_peak_is_exact_for_samples_of_a_cosine(offset, theta, amplitude):
    before, at, after = (amplitude * math.cos(theta * (d - offset)) for d in (-1, 0, 1))
    assert cosine_peak(before, at, after) == pytest.approx(offset, abs=1e-9)


def test_pearson_at_lag_of_a_shifted_copy_is_one():
    rng = np.random.default_rng(0)
    led = rng.standard_normal(300)
    sphere = np.concatenate([rng.standard_normal(7), 3 * led[:-7] + 1])
    assert pearson_at_lag(led, sphere, 7) == pytest.approx(1.0)
    assert pearson_at_lag(sphere, led, -7) == pytest.approx(1.0)


@pytest.mark.parametrize("latency", [0.0123, 0.0871, -0.031, 0.52])
def test_latency_of_a_damped_swing_to_a_small_fraction_of_a_frame(latency):
    fps, period = 120.0, 0.9
    t = np.arange(int(7.3 * fps)) / fps
    envelope = np.exp(-0.05 * t)
    led = 30 * envelope * np.sin(2 * math.pi * t / period)
    sphere = 20 * np.exp(-0.05 * (t - latency)) * np.sin(2 * math.pi * (t - latency) / period)
    found = xcorr_latency(led, sphere, fps, period, reference_s=latency + 0.1)
    assert found == pytest.approx(latency, abs=0.02 / fps)
