"""The JAX twins agree with the real-time predictors to 1e-9, also vmapped, on a trace with every
awkward feature: sign flips, duplicate and out-of-order times, a drop-out. They need float64, which
each test turns on for itself (`jax.enable_x64`), as a user of the twins does."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from predictors import PredictorError, Trace, make
from predictors import quaternion as quat
from predictors.evaluation import replay
from predictors.jax_filters import (
    TWINNED,
    DespParams,
    KalmanParams,
    TraceArrays,
    desp_predictions,
    kalman_predictions,
    predictions,
)
from predictors.registry import params_of
from predictors.synthetic import head_motion

HORIZON = 0.05


@pytest.fixture(autouse=True)
def float64():
    with jax.enable_x64(True):
        yield


@pytest.fixture(scope="module")
def awkward() -> Trace:
    base = head_motion(3.0, 60.0, seed=4).with_noise(0.001, 0.002, seed=4)
    t, p, q = base.t.copy(), base.position.copy(), base.orientation.copy()
    q[1::3] *= -1.0  # sign flips
    t[20] = t[19]  # a duplicate time
    t[40] = t[38]  # an out-of-order sample
    t[100:] += 1.5  # a drop-out longer than max_gap
    return Trace.from_samples("awkward", t, p, q)


def arrays(trace: Trace) -> TraceArrays:
    order = trace.arrival_order()
    return TraceArrays(
        jnp.asarray(trace.t[order]), jnp.asarray(trace.position[order]), jnp.asarray(trace.orientation[order]),
        jnp.asarray(trace.t_arrival[order] + HORIZON), jnp.ones(len(trace), dtype=bool),
    )


def assert_agree(trace, predictor, positions, orientations):
    _, expected_p, expected_q = replay(predictor, trace, [HORIZON])
    np.testing.assert_allclose(np.asarray(positions), expected_p[0], rtol=0, atol=1e-9)
    assert quat.angle_between(np.asarray(orientations), expected_q[0]).max() < 1e-9


@pytest.mark.parametrize(("name", "order"), [("kalman-cv", 2), ("kalman-ca", 3)])
def test_kalman_twin_agrees_with_the_real_time_filter_for_two_parameter_sets_at_once(awkward, name, order):
    drive = "acceleration_noise" if order == 2 else "jerk_noise"
    sets = [{"position_noise": 0.001, drive: 3.0, "angular_acceleration_noise": 4.0},
            {"position_noise": 0.01, drive: 0.5, "angular_acceleration_noise": 20.0}]
    predictors = [make(name, **s) for s in sets]
    stacked = KalmanParams(*[
        jnp.array([getattr(p, field) for p in predictors])
        for field in ("position_noise", drive, "orientation_noise", "angular_acceleration_noise", "max_gap", "max_horizon")
    ])
    run = jax.jit(jax.vmap(lambda params: kalman_predictions(order, params, arrays(awkward))))
    positions, orientations = run(stacked)
    for k, predictor in enumerate(predictors):
        assert_agree(awkward, predictor, positions[k], orientations[k])


@pytest.mark.parametrize("interval", [None, 1.0 / 60.0])
def test_desp_twin_agrees_with_the_real_time_smoother(awkward, interval):
    predictor = make("desp", position_alpha=0.6, orientation_alpha=0.7, sample_interval=interval)
    params = DespParams(*map(jnp.asarray, (0.6, 0.7, interval or 0.0, predictor.max_gap, predictor.max_horizon)))
    positions, orientations = jax.jit(desp_predictions)(params, arrays(awkward))
    assert_agree(awkward, predictor, positions, orientations)


def test_damped_kalman_twin_agrees_on_both_sides_of_the_series_switch(awkward):
    """At 60 Hz a damping of 0.5/s steps with x = 0.008 (series) and 8/s with x = 0.13 (closed form).
    The orientation filter is the same in kalman-ca, so kalman-cv stands for both."""
    predictors = [make("kalman-cv", angular_velocity_damping=damping) for damping in (0.5, 8.0)]
    stacked = KalmanParams(*[
        jnp.array([getattr(p, field) for p in predictors])
        for field in ("position_noise", "acceleration_noise", "orientation_noise", "angular_acceleration_noise", "max_gap",
                      "max_horizon", "angular_velocity_damping")
    ])
    run = jax.jit(jax.vmap(lambda params: kalman_predictions(2, params, arrays(awkward))))
    positions, orientations = run(stacked)
    for k, predictor in enumerate(predictors):
        assert_agree(awkward, predictor, positions[k], orientations[k])


def test_the_damped_twin_has_the_gradient_of_its_finite_differences_through_duplicate_times(awkward):
    """Duplicate and out-of-order times step by dt = 0, where the damped step's closed form is 0 / 0:
    the gradient in the log damping must stay finite and right."""
    truth = jnp.asarray(awkward.truth_at(awkward.t_arrival[awkward.arrival_order()] + HORIZON)[1])

    def loss(log_damping):
        params = KalmanParams(*map(jnp.asarray, (0.001, 1.0, 0.002, 5.0, 1.0, 0.5)), jnp.exp(log_damping))
        _, orientations = kalman_predictions(2, params, arrays(awkward))
        return jnp.mean(1.0 - jnp.sum(orientations * truth, axis=-1) ** 2)

    value_and_grad = jax.jit(jax.value_and_grad(loss))
    for log_damping in (np.log(0.5), np.log(8.0)):
        _, gradient = value_and_grad(log_damping)
        step = 1e-5
        difference = (value_and_grad(log_damping + step)[0] - value_and_grad(log_damping - step)[0]) / (2 * step)
        assert np.isfinite(gradient)
        assert float(gradient) == pytest.approx(float(difference), rel=1e-5)


@pytest.mark.parametrize(
    ("name", "params"),
    [
        ("kalman-cv", {"acceleration_noise": 3.0, "angular_velocity_damping": 2.0}),
        ("kalman-ca", {"jerk_noise": 5.0, "position_noise": 0.002}),
        ("desp", {"position_alpha": 0.3, "orientation_alpha": 0.8}),
        ("desp", {"sample_interval": 1.0 / 60.0}),
    ],
)
def test_a_twin_built_from_the_declared_parameters_agrees_with_the_real_time_predictor(awkward, name, params):
    assert name in TWINNED
    values = params_of(name).resolve(params)
    positions, orientations = jax.jit(lambda trace: predictions(name, values, trace))(arrays(awkward))
    assert_agree(awkward, make(name, **params), positions, orientations)


def test_a_twin_refuses_float32_arrays_naming_the_switch(awkward):
    with jax.enable_x64(False):
        trace = arrays(awkward)
        params = DespParams(*map(jnp.asarray, (0.6, 0.7, 0.0, 1.0, 0.5)))
        with pytest.raises(PredictorError, match=r"need float64 times, got float32.*jax.enable_x64\(True\)"):
            desp_predictions(params, trace)


def test_only_twinned_predictors_have_twins(awkward):
    with pytest.raises(PredictorError, match="'auto' has no JAX twin; twinned predictors: kalman-cv, kalman-ca, desp"):
        predictions("auto", params_of("auto").resolve({}), arrays(awkward))
