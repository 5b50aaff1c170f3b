"""The damped angular velocity of the orientation filter (`angular_velocity_damping`): its step
against the exact integrals and the matrix exponential, its covariance against the textbook
recursion and over extreme steps, exact prediction of a turn that slows down, and the hard cases."""

import math
from decimal import Decimal, getcontext

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.linalg import expm

from predictors import PoseSample, PredictorError, make
from predictors import quaternion as quat
from predictors.kinematic_covariance import SERIES_BELOW, KinematicCovariance, damped_reach, damped_step

laws = settings(deadline=None, max_examples=60, derandomize=True)

Q0 = quat.normalise([0.9, 0.1, -0.3, 0.2])
P0 = np.array([0.1, 1.5, -0.3])
OMEGA = np.array([1.5, -3.0, 0.9])  # rad/s at t = 0, world frame
DAMPING = 2.0  # 1/s


def slowing_turn(t: float) -> np.ndarray:
    """A turn about a fixed world axis whose angular velocity decays as OMEGA e^(-DAMPING t)."""
    return quat.multiply(quat.from_rotation_vector(OMEGA * -math.expm1(-DAMPING * t) / DAMPING), Q0)


def exact_step(dt: float, damping: float) -> tuple[Decimal, ...]:
    """(reach, decay, Q00, Q01, Q11) of the damped model to 60 digits, from the integrals."""
    getcontext().prec = 60
    dt, b = Decimal(dt), Decimal(damping)
    decay = (-b * dt).exp()
    a = 1 - decay
    return a / b, decay, (b * dt - a - a * a / 2) / b**3, a * a / (2 * b * b), (1 - decay * decay) / (2 * b)


@pytest.mark.parametrize("x", [1e-7, 1e-3, 0.5 * SERIES_BELOW, 0.999999 * SERIES_BELOW, SERIES_BELOW, 0.021, 0.3, 4.0, 40.0])
def test_damped_step_matches_the_exact_integrals_on_both_sides_of_the_series_switch(x):
    for dt in (1e-6, 0.0167, 2.0):
        step = damped_step(dt, x / dt)
        for got, exact in zip(step, exact_step(dt, x / dt)):
            assert abs(Decimal(got) - exact) <= Decimal(1e-12) * abs(exact)


@pytest.mark.parametrize(("dt", "damping"), [(0.0167, 0.3), (0.0167, 4.0), (0.1, 25.0), (1.0, 2.0)])
def test_damped_step_is_the_matrix_exponential_of_the_continuous_model(dt, damping):
    """Van Loan: exp([[-A, G G^T], [0, A^T]] dt) holds F^T and F^-1 Q for dx = A x dt + G dW."""
    a = np.array([[0.0, 1.0], [0.0, -damping]])
    g = np.array([[0.0], [1.0]])
    block = expm(np.block([[-a, g @ g.T], [np.zeros((2, 2)), a.T]]) * dt)
    f = block[2:, 2:].T
    q = f @ block[:2, 2:]
    reach, decay, q00, q01, q11 = damped_step(dt, damping)
    np.testing.assert_allclose(f, [[1.0, reach], [0.0, decay]], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(q, [[q00, q01], [q01, q11]], rtol=1e-9)


def test_damped_covariance_follows_the_textbook_recursion():
    rng = np.random.default_rng(5)
    density, variance = 20.0, 4e-6
    covariance = KinematicCovariance(2, density, variance, (4e-6, 9.0))
    p = covariance.matrix()
    for dt, damping in zip(rng.uniform(1e-4, 0.2, 200), rng.choice([0.5, 4.0, 60.0], 200)):
        step = damped_step(dt, damping)
        covariance.predict_damped(step)
        gain = covariance.update()
        reach, decay, q00, q01, q11 = step
        f = np.array([[1.0, reach], [0.0, decay]])
        p = f @ p @ f.T + density * np.array([[q00, q01], [q01, q11]])
        k = p[:, 0] / (p[0, 0] + variance)
        p = p - np.outer(k, p[0])
        np.testing.assert_allclose(gain, k, rtol=1e-10)
    np.testing.assert_allclose(covariance.matrix(), p, rtol=1e-9, atol=1e-300)


def test_damped_covariance_stays_symmetric_positive_definite_over_extreme_steps():
    rng = np.random.default_rng(13)
    steps = rng.choice([1e-6, 0.001, 0.0167, 2.0, 3600.0], size=200_000, p=[0.05, 0.2, 0.7, 0.049, 0.001])
    covariance = KinematicCovariance(2, 30.0, 1e-8, (1e-8, 9.0))
    smallest = np.inf
    for dt in steps.tolist():
        covariance.predict_damped(damped_step(dt, 8.0))
        covariance.update()
        smallest = min(smallest, min(covariance.diagonal_factor()))
    assert smallest > 0.0
    p = covariance.matrix()
    np.testing.assert_array_equal(p, p.T)
    assert np.all(np.linalg.eigvalsh(p) > 0.0)


@pytest.mark.parametrize("name", ["kalman-cv", "kalman-ca", "auto", "split"])
@pytest.mark.parametrize("irregular", [False, True], ids=["100Hz", "jittered"])
def test_a_noiseless_turn_that_slows_down_is_predicted_exactly_by_the_damped_filter(name, irregular):
    rng = np.random.default_rng(2)
    times = np.cumsum(rng.uniform(0.005, 0.02, 100)) if irregular else np.arange(100) * 0.01
    predictor = make(name, angular_velocity_damping=DAMPING, **({"memory": 0.2} if name == "auto" else {}))
    for t in times:
        predictor.update(PoseSample(t, t, P0, slowing_turn(t)))
    if name == "auto":
        assert predictor.choice.orientation == "filter"
    for h in (0.0, 0.001, 0.1, 0.5):
        predicted = predictor.predict(times[-1] + h).orientation
        assert quat.angle_between(predicted, slowing_turn(times[-1] + h)) < 1e-12


def test_the_undamped_filter_overshoots_the_same_turn():
    """The case above is not passed by any filter: without damping the prediction overshoots."""
    predictor = make("kalman-cv")
    for t in np.arange(100) * 0.01:
        predictor.update(PoseSample(t, t, P0, slowing_turn(t)))
    assert quat.angle_between(predictor.predict(0.99 + 0.1).orientation, slowing_turn(0.99 + 0.1)) > 1e-3


def test_a_vanishing_damping_predicts_as_the_undamped_filter():
    rng = np.random.default_rng(3)
    damped, undamped = make("kalman-cv", angular_velocity_damping=1e-12), make("kalman-cv")
    for t in np.cumsum(rng.uniform(0.005, 0.02, 100)):
        for predictor in (damped, undamped):
            predictor.update(PoseSample(t, t, P0, slowing_turn(t)))
    for h in (-0.01, 0.0, 0.05, 0.5):
        a, b = damped.predict(t + h), undamped.predict(t + h)
        assert quat.angle_between(a.orientation, b.orientation) < 1e-9


@laws
@given(
    damping=st.floats(0.0, 200.0),
    first=st.floats(-0.5, 0.5),
    second=st.floats(-0.5, 0.5),
)
@example(damping=63.0, first=-0.25, second=0.5)  # two terms of 1e5 cancelling to 0.016
def test_law_damped_reach_composes_over_consecutive_horizons(damping, first, second):
    """Carrying a velocity h1 then h2 seconds goes as far as carrying it h1 + h2 seconds.

    Backwards over a strongly damped step the two terms grow like e^(damping |h1|) and cancel, so
    the rounding allowed is relative to the terms, not to their sum.
    """
    together = damped_reach(first + second, damping)
    before = damped_reach(first, damping)
    after = math.exp(-damping * first) * damped_reach(second, damping)
    assert together == pytest.approx(before + after, rel=1e-9, abs=1e-12 + 1e-14 * (abs(before) + abs(after)))


@laws
@given(damping=st.floats(0.0, 1e4), h=st.floats(0.0, 10.0))
@example(damping=5e-324, h=1.5)  # a subnormal damping once rounded the reach to 2 h
def test_law_a_damped_velocity_never_carries_further_ahead_than_an_undamped_one(damping, h):
    assert 0.0 <= damped_reach(h, damping) <= h


@pytest.mark.parametrize("name", ["kalman-cv", "kalman-ca", "auto", "split"])
@pytest.mark.parametrize("step", [0.0, 1e-6, 3600.0], ids=["zero", "1us", "an-hour"])
def test_damped_filters_take_steps_of_zero_one_microsecond_and_an_hour(name, step):
    predictor = make(name, angular_velocity_damping=60.0, max_gap=1e4)
    for t in np.arange(30) * 0.01:
        predictor.update(PoseSample(t, t, P0, slowing_turn(t)))
    last = 0.29 + step
    predictor.update(PoseSample(last, last, P0, slowing_turn(last)))
    for h in (-0.1, 0.0, 0.02, 0.5):
        pose = predictor.predict(last + h)
        assert np.isfinite(pose.orientation).all()
        assert np.linalg.norm(pose.orientation) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("name", ["kalman-cv", "kalman-ca", "auto", "split"])
@pytest.mark.parametrize("value", [-1.0, math.nan, math.inf, "fast"])
def test_a_negative_or_non_finite_damping_is_a_clear_error(name, value):
    with pytest.raises(PredictorError, match=f"{name}: angular_velocity_damping must be a number of 1/s from 0 to 10000"):
        make(name, angular_velocity_damping=value)
