"""`rls` learns linear coefficients on the recent angular velocities per horizon, on the stream:
exact at constant angular velocity, learnt to the exact extrapolation at constant angular
acceleration, alike at 30 Hz and 1 kHz, and its sample rules."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from predictors import PoseSample, PredictorError, make
from predictors import quaternion as quat
from predictors import scalar_quaternion as squat

laws = settings(deadline=None, max_examples=15, derandomize=True)

Q0 = squat.normalised((0.9, 0.1, -0.3, 0.2))
AXIS = np.array([0.3, -0.9, 0.3]) / np.linalg.norm([0.3, -0.9, 0.3])
P0 = (0.1, 1.5, -0.3)


def accelerating(t: float, omega0: float = -3.0, alpha: float = 1.0) -> PoseSample:
    """A turn about a fixed axis at angular velocity omega0 + alpha t (rad/s), the head in place."""
    angle = omega0 * t + 0.5 * alpha * t * t
    return PoseSample(t, t, np.array(P0), np.array(squat.rotated_by(*(angle * AXIS).tolist(), Q0)))


def angle_deg(a, b) -> float:
    return math.degrees(float(quat.angle_between(np.asarray(a), np.asarray(b))))


@laws
@given(
    omega=st.tuples(*[st.floats(-5.0, 5.0)] * 3),
    rate_hz=st.floats(30.0, 1000.0),
    horizon=st.floats(0.0, 0.3),
)
def test_law_constant_angular_velocity_is_predicted_exactly_after_warm_up(omega, rate_hz, horizon):
    predictor = make("rls")
    t = 0.0
    for k in range(int(2.0 * rate_hz)):
        t = k / rate_hz
        predictor.update(SimpleNamespace(t_sensor=t, position=P0, orientation=squat.rotated_by(
            omega[0] * t, omega[1] * t, omega[2] * t, Q0)))
    later = t + horizon
    truth = squat.rotated_by(omega[0] * later, omega[1] * later, omega[2] * later, Q0)
    assert angle_deg(predictor.predict(later).orientation, truth) < 1e-9


@pytest.mark.parametrize("horizon", [0.02, 0.04, 0.08])
def test_constant_angular_acceleration_is_learnt_as_its_exact_extrapolation(horizon):
    """At a constant interval dt the turn H ahead is H (w1 + (1/2 + H / (2 dt)) (w1 - w2)): the
    changes' coefficients (collinear here, so only their sum is determined) learn that sum. At
    50 Hz the horizons fall on samples, where the truth learnt from is exact (between samples it
    is interpolated, as `adaptive` scores it). The default prior, 0.25 s of evidence for constant
    velocity over a memory of 10 s, shrinks the changes' coefficients by about 2.5 %."""
    exact = 0.5 + horizon * 50.0 / 2.0
    for prior, tolerance in ((1e-3, 1e-3), (0.25, 0.03)):
        predictor = make("rls", prior=prior)
        for k in range(500):
            predictor.update(accelerating(k / 50.0))
        coefficients = predictor.coefficients_at(horizon)
        assert coefficients[0] == pytest.approx(1.0, abs=1e-3)
        assert exact * (1.0 - tolerance) < sum(coefficients[1:]) <= exact * (1.0 + 1e-3)


def test_constant_angular_acceleration_is_predicted_better_than_constant_velocity_once_learnt():
    rls, slerp = make("rls"), make("slerp")
    errors = {"rls": [], "slerp": []}
    for k in range(600):
        sample = accelerating(k / 60.0)
        rls.update(sample)
        slerp.update(sample)
        if k >= 300:
            truth = accelerating(k / 60.0 + 0.05).orientation
            errors["rls"].append(angle_deg(rls.predict(k / 60.0 + 0.05).orientation, truth))
            errors["slerp"].append(angle_deg(slerp.predict(k / 60.0 + 0.05).orientation, truth))
    rms = {name: math.sqrt(np.mean(np.square(e))) for name, e in errors.items()}
    assert rms["slerp"] > 0.05  # degrees: constant velocity lags the acceleration visibly
    assert rms["rls"] < 0.1 * rms["slerp"]


def test_30_hz_and_1_khz_give_the_same_predictions_on_the_same_motion():
    """Fed the same accelerating turn, the two rates' predictions 50 ms ahead of the same instants,
    once learnt, agree far more closely than constant velocity agrees with the truth. (Each misses
    the truth by up to a seventh of constant velocity's error: between its learnt horizons, 40 and
    80 ms, the coefficients are blended on a log scale where the exact ones are linear in H.)"""
    predictors = {rate: make("rls") for rate in (30, 1000)}
    fed = {30: 0, 1000: 0}
    for checkpoint in (6.0, 7.0, 8.0, 9.0, 10.0):
        for rate, predictor in predictors.items():
            while fed[rate] <= round(checkpoint * rate):
                predictor.update(accelerating(fed[rate] / rate))
                fed[rate] += 1
        truth = accelerating(checkpoint + 0.05).orientation
        slow, fast = (predictors[rate].predict(checkpoint + 0.05).orientation for rate in (30, 1000))
        # constant velocity at the true angular velocity of the instant, -3 + t rad/s
        held = squat.rotated_by(*(0.05 * (-3.0 + checkpoint) * AXIS).tolist(), accelerating(checkpoint).orientation)
        lag = angle_deg(held, truth)
        assert angle_deg(slow, fast) < 0.1 * lag
        assert angle_deg(slow, truth) < 0.2 * lag and angle_deg(fast, truth) < 0.2 * lag


def test_a_bad_sample_is_refused_and_changes_nothing():
    predictor, twin = make("rls"), make("rls")
    for k in range(120):
        predictor.update(accelerating(k / 60.0))
        twin.update(accelerating(k / 60.0))
    bad = SimpleNamespace(t_sensor=2.0, position=P0, orientation=(math.nan, 0.0, 0.0, 1.0))
    with pytest.raises(PredictorError, match="'rls' was given an orientation"):
        predictor.update(bad)
    for k in range(120, 240):
        predictor.update(accelerating(k / 60.0))
        twin.update(accelerating(k / 60.0))
    assert predictor.predict(4.05).orientation.tolist() == twin.predict(4.05).orientation.tolist()
    assert predictor.coefficients_at(0.05) == twin.coefficients_at(0.05)


def test_a_gap_restarts_the_velocities_but_keeps_what_was_learnt():
    predictor = make("rls", max_gap=0.5)
    for k in range(600):
        predictor.update(accelerating(k / 60.0))
    learnt = predictor.coefficients_at(0.05)
    later = accelerating(12.0)
    predictor.update(later)
    assert predictor.predict(12.05).orientation.tolist() == later.orientation.tolist()
    assert predictor.coefficients_at(0.05) == learnt
    predictor.update(accelerating(12.0 + 1.0 / 60.0))
    assert angle_deg(predictor.predict(12.05).orientation, accelerating(12.05).orientation) < 0.2


def test_reset_forgets_everything():
    predictor = make("rls")
    for k in range(300):
        predictor.update(accelerating(k / 60.0))
    predictor.reset()
    with pytest.raises(PredictorError, match="'rls' has no sample yet"):
        predictor.predict(0.0)
    assert predictor.coefficients_at(0.05) == [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]


def test_history_is_a_whole_number_of_samples():
    assert len(make("rls", history=3).coefficients_at(0.05)) == 3
    with pytest.raises(PredictorError, match="rls: history must be a whole number of samples, got 2.5"):
        make("rls", history=2.5)
    with pytest.raises(PredictorError, match="history must be"):
        make("rls", history=0)


@pytest.mark.slow
def test_a_million_samples_stay_exact_and_finite():
    """A thousand seconds at 1000 Hz of noiseless constant angular velocity: still exact."""
    predictor = make("rls")
    omega = (0.5, -1.0, 0.3)
    t = 0.0
    for k in range(1_000_000):
        t = 0.001 * k
        predictor.update(SimpleNamespace(t_sensor=t, position=P0, orientation=squat.rotated_by(
            omega[0] * t, omega[1] * t, omega[2] * t, Q0)))
    later = t + 0.05
    truth = squat.rotated_by(omega[0] * later, omega[1] * later, omega[2] * later, Q0)
    assert angle_deg(predictor.predict(later).orientation, truth) < 1e-6
    assert all(math.isfinite(c) for c in predictor.coefficients_at(0.05))
