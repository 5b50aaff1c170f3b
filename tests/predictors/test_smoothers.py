"""The smoothers kept relative to the newest sample agree with the quaternion Kalman filter of
`predictors.kalman` given the same model, and the two-sample estimate is slerp's."""

import math

import numpy as np
import pytest

from predictors import PoseSample, make
from predictors import quaternion as quat
from predictors import scalar_quaternion as squat
from predictors.kalman import OrientationFilter
from predictors.smoothers import BANDWIDTHS_HZ, Smoothers, two_sample

DT = 0.01


def turning(t: float) -> np.ndarray:
    """A head turning at up to 3 rad/s about an axis that swings round."""
    axis = np.array([math.sin(1.3 * t), 1.0, 0.4 * math.cos(0.7 * t)])
    return quat.from_rotation_vector(1.5 * math.sin(2.0 * t) * axis / np.linalg.norm(axis))


def test_each_smoother_follows_the_quaternion_kalman_filter_of_its_bandwidth():
    """Same F, Q, R and prior: the offsets relative to the newest sample, composed to second order,
    track the exact multiplicative filter over 3 s of turning at up to 3 rad/s: the orientation to
    within 1e-5 rad, the angular velocity to within 5e-4 rad/s (50 ms ahead, 2.5e-5 rad)."""
    noise = 3e-4  # rad: so that the filter's prior speed variance, 3^2 / noise^2, is the smoothers' 1e4 / DT^2
    rng = np.random.default_rng(1)
    samples = [tuple(quat.multiply(turning(k * DT), quat.from_rotation_vector(rng.normal(0, 0.002, 3)))) for k in range(300)]
    smoothers = Smoothers()
    references = [
        OrientationFilter(noise, noise * math.sqrt((2 * math.pi * f) ** 4 * DT), samples[0]) for f in BANDWIDTHS_HZ
    ]
    for previous, sample in zip(samples, samples[1:]):
        r = squat.rotation_vector_between(previous, sample)
        smoothers.advance(DT, r, (0.0, 0.0, 0.0), two_sample(DT, r, (0.0, 0.0, 0.0)))
        for reference in references:
            reference.step(DT, sample)
    newest = samples[-1]
    for (turning_estimate, _), reference in zip(smoothers.estimates[1:], references):
        offset, velocity = turning_estimate[:3], turning_estimate[3:]
        smoothed = squat.rotated_by(*offset, newest)
        assert quat.angle_between(smoothed, reference.q) < 1e-5
        np.testing.assert_allclose(velocity, (reference.wx, reference.wy, reference.wz), rtol=0, atol=5e-4)


def test_the_two_sample_estimate_predicts_as_slerp():
    a, b = turning(0.0), turning(0.02)
    r = squat.rotation_vector_between(tuple(a), tuple(b))
    (_, _, _, w0, w1, w2), _ = two_sample(0.02, r, (0.0, 0.0, 0.0))
    slerp = make("slerp")
    slerp.update(PoseSample(0.0, 0.0, np.zeros(3), a))
    slerp.update(PoseSample(0.02, 0.02, np.zeros(3), b))
    predicted = squat.rotated_by(0.05 * w0, 0.05 * w1, 0.05 * w2, tuple(b))
    assert quat.angle_between(predicted, slerp.predict(0.07).orientation) < 1e-12


@pytest.mark.parametrize("dt", [0.0005, 0.001])
def test_a_bandwidth_in_hz_is_the_same_filter_at_any_high_rate(dt):
    """Where the rate is well above the bandwidth, the 10 Hz smoother's steady-state gains per second
    are those of the continuous-time filter of natural frequency w0 = 2 pi 10 rad/s (position
    sqrt(2) w0, velocity w0^2), whatever the sample interval."""
    smoothers = Smoothers()
    still = (0.0, 0.0, 0.0)
    for _ in range(int(2.0 / dt)):
        smoothers.advance(dt, still, still, two_sample(dt, still, still))
    covariance = smoothers._covariances[BANDWIDTHS_HZ.index(10.0)]
    covariance.predict(dt)
    k0, k1 = covariance.update()
    w0 = 2 * math.pi * 10.0
    assert k0 / dt == pytest.approx(math.sqrt(2.0) * w0, rel=0.1)
    assert k1 / dt == pytest.approx(w0 * w0, rel=0.1)


def test_leaving_a_still_position_unupdated_changes_no_estimate_by_a_bit():
    """Until the position first moves the smoothers leave it as it is (every position estimate
    exactly zero): smoothers made to update it from the first sample end with the same estimates,
    bit for bit (repr tells -0.0 from 0.0), through a still stretch, a step of -0.0, duplicates
    and motion."""
    rng = np.random.default_rng(2)
    skipping, updating = Smoothers(), Smoothers()
    updating._moved = True
    for k in range(300):
        dt = 0.0 if k % 37 == 5 else 0.008 + 0.004 * rng.random()
        r = tuple(rng.normal(0.0, 0.01, 3).tolist())
        rp = (0.0, -0.0, 0.0) if k < 150 else tuple(rng.normal(0.0, 0.001, 3).tolist())
        for smoothers in (skipping, updating):
            smoothers.advance(dt, r, rp, two_sample(dt or 0.01, r, rp))
        assert repr(skipping.estimates) == repr(updating.estimates)
    assert any(moving != (0.0,) * 6 for _, moving in skipping.estimates[1:])
