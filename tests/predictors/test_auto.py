"""`auto` picks the simplest model the motion needs, from a cold start, and says why."""

import numpy as np

from predictors import PoseSample, make
from predictors import quaternion as quat


def feed(predictor, position, orientation, seconds=4.0, rate=100.0, noise=0.0, seed=0):
    rng = np.random.default_rng(seed)
    for t in np.arange(int(seconds * rate)) / rate:
        p = np.asarray(position(t)) + noise * rng.standard_normal(3)
        predictor.update(PoseSample(t, t, p, orientation(t)))
    return predictor


def still(_t):
    return [1.0, 0.0, 0.0, 0.0]


def turning(t):
    return quat.from_rotation_vector([0.0, 2.0 * t, 0.0])


def test_a_still_scene_uses_no_prediction():
    auto = feed(make("auto"), lambda t: [0.1, 1.5, -0.3], still)
    assert (auto.choice.position, auto.choice.orientation) == ("none", "none")


def test_constant_velocity_motion_uses_constant_velocity_and_the_orientation_filter():
    auto = feed(make("auto"), lambda t: [0.3 * t, 1.5, 0.0], turning)
    assert (auto.choice.position, auto.choice.orientation) == ("constant-velocity", "filter")
    assert "simplest within 10%" in auto.choice.reason


def test_accelerating_motion_uses_constant_acceleration():
    auto = feed(make("auto", position_noise=1e-5), lambda t: [0.5 * t * t, 1.5, 0.0], still)
    assert auto.choice.position == "constant-acceleration"


def test_a_cold_start_uses_no_prediction_while_warming_up():
    auto = feed(make("auto", memory=2.0), lambda t: [0.3 * t, 1.5, 0.0], turning, seconds=1.0)
    assert (auto.choice.position, auto.choice.orientation) == ("none", "none")
    assert auto.choice.reason.startswith("warming up")
    assert make("auto").choice.reason.startswith("no sample yet")


def test_the_choice_changes_with_the_scene():
    auto = feed(make("auto", memory=0.5), lambda t: [0.3 * t, 1.5, 0.0], still, seconds=3.0)
    assert auto.choice.position == "constant-velocity"
    for t in 3.0 + np.arange(300) / 100.0:
        auto.update(PoseSample(t, t, [0.9, 1.5, 0.0], still(t)))
    assert auto.choice.position == "none"
