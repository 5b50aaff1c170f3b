"""The stress streams: each fault is what it says, scored against the clean motion."""

import math

import numpy as np
import pytest

from predictors import PredictorError
from predictors import quaternion as quat
from predictors.stress import (
    head_motion_truth,
    sampled,
    stress_streams,
    sudden_stops,
    with_coloured_noise,
    with_repeats,
)


@pytest.fixture(scope="module")
def head():
    return head_motion_truth(5.0, seed=1)


def test_sampling_at_a_rate_with_jitter_keeps_order_and_the_truth(head):
    stream = sampled(head, 60.0, jitter=0.4, seed=2)
    intervals = np.diff(stream.t)
    assert len(stream) == 301 and np.all(intervals > 0.0)
    assert intervals.min() < 0.5 / 60.0 and intervals.max() > 1.5 / 60.0
    position, orientation = head.truth_at(stream.t)
    np.testing.assert_allclose(stream.position, position)
    assert stream.truth_t.size == head.truth_t.size


def test_coloured_noise_has_its_standard_deviation_and_correlation(head):
    stream = sampled(head, 1000.0)
    noisy = with_coloured_noise(stream, 0.001, 0.0, -0.6, seed=3)
    noise = noisy.position - stream.position
    assert noise.std() == pytest.approx(0.001, rel=0.05)
    lag_one = np.sum(noise[1:] * noise[:-1]) / np.sum(noise * noise)
    assert lag_one == pytest.approx(-0.6, abs=0.03)
    assert quat.angle_between(noisy.orientation, stream.orientation).max() < 1e-12


def test_repeats_hold_the_previous_pose_under_their_own_time(head):
    stream = sampled(head, 100.0)
    repeated = with_repeats(stream, 0.2, seed=4)
    same = np.all(repeated.position[1:] == repeated.position[:-1], axis=1)
    assert same.mean() == pytest.approx(0.2, abs=0.06)
    np.testing.assert_array_equal(repeated.t, stream.t)


def test_sudden_stops_switch_between_rest_and_constant_velocity_at_once():
    trace = sudden_stops(6.0, seed=5)
    steps = quat.to_rotation_vector(quat.multiply(trace.orientation[1:], quat.conjugate(trace.orientation[:-1])))
    speed = np.degrees(np.linalg.norm(steps, axis=1)) * 1000.0
    moving = speed > 1.0
    assert 0.1 < moving.mean() < 0.8 and speed.max() <= 250.0 + 1e-6
    assert np.all((speed[moving] >= 30.0 - 1e-6))
    assert np.count_nonzero(np.diff(moving.astype(int))) >= 4


def test_the_stress_set_spans_rates_and_faults():
    streams = stress_streams(2.0, seed=0)
    rates = [1.0 / np.median(np.diff(s.t)) for s in streams]
    assert min(rates) == pytest.approx(30.0) and max(rates) == pytest.approx(1000.0)
    assert len({s.name for s in streams}) == len(streams)


@pytest.mark.parametrize(
    "call",
    [
        lambda h: sampled(h, 0.0),
        lambda h: sampled(h, 60.0, jitter=0.5),
        lambda h: with_coloured_noise(h, 0.001, 0.0, 1.0, seed=0),
        lambda h: with_repeats(h, 1.0, seed=0),
        lambda h: sudden_stops(-1.0, seed=0),
    ],
    ids=["rate", "jitter", "correlation", "repeats", "duration"],
)
def test_bad_stress_settings_are_refused(head, call):
    with pytest.raises(PredictorError):
        call(head)
