"""The Kalman filters' maths: factored covariance against the textbook recursion and a brute-force
batch solution, a million steps staying positive definite, and the scalar quaternion kernels."""

import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st

from predictors import quaternion as quat
from predictors import scalar_quaternion as squat
from predictors.kalman import (
    INITIAL_ACCELERATION_STD,
    INITIAL_SPEED_STD,
    ConstantAccelerationPosition,
    ConstantVelocityPosition,
)
from predictors.kinematic_covariance import KinematicCovariance

laws = settings(deadline=None, max_examples=60, derandomize=True)


def model(order: int, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """F and Q / density of the continuous white-noise model, written out."""
    if order == 2:
        return np.array([[1, dt], [0, 1]]), np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
    f = np.array([[1, dt, dt * dt / 2], [0, 1, dt], [0, 0, 1]])
    q = np.array([[dt**5 / 20, dt**4 / 8, dt**3 / 6], [dt**4 / 8, dt**3 / 3, dt**2 / 2], [dt**3 / 6, dt**2 / 2, dt]])
    return f, q


@pytest.mark.parametrize("order", [2, 3])
def test_factored_covariance_follows_the_textbook_recursion(order):
    rng = np.random.default_rng(3)
    density, variance = 0.7, 1e-4
    covariance = KinematicCovariance(order, density, variance, (1e-4, 1.0, 100.0)[:order])
    p = covariance.matrix()
    for dt in rng.uniform(1e-4, 0.2, 200):
        covariance.predict(dt)
        gain = covariance.update()
        f, q = model(order, dt)
        p = f @ p @ f.T + density * q
        k = p[:, 0] / (p[0, 0] + variance)
        p = p - np.outer(k, p[0])
        np.testing.assert_allclose(gain, k, rtol=1e-10)
    np.testing.assert_allclose(covariance.matrix(), p, rtol=1e-9, atol=1e-300)


@pytest.mark.parametrize(("order", "filter_class"), [(2, ConstantVelocityPosition), (3, ConstantAccelerationPosition)])
def test_kalman_filter_equals_the_brute_force_batch_solution(order, filter_class):
    """Condition the joint Gaussian of all states and measurements on the measurements."""
    rng = np.random.default_rng(7)
    noise, drive = 0.01, 2.0
    times = np.cumsum(np.r_[0.0, rng.uniform(0.005, 0.05, 14)])
    z = rng.normal(size=(times.size, 3)).cumsum(axis=0) * 0.05
    position_filter = filter_class(noise, drive, tuple(z[0]))
    for k in range(1, times.size):
        position_filter.step(times[k] - times[k - 1], tuple(z[k]))
    # Joint prior of x_0..x_N (per axis): x_0 ~ N(m0, P0), x_k = F x_{k-1} + w_k.
    n, size = times.size, order * times.size
    p0 = np.diag([noise**2, INITIAL_SPEED_STD**2, INITIAL_ACCELERATION_STD**2][:order])
    transition = np.eye(size)
    noise_cov = np.zeros((size, size))
    noise_cov[:order, :order] = p0
    for k in range(1, n):
        f, q = model(order, times[k] - times[k - 1])
        transition[k * order:(k + 1) * order] = f @ transition[(k - 1) * order:k * order]
        noise_cov[k * order:(k + 1) * order, k * order:(k + 1) * order] = drive**2 * q
    # x = T e with e the independent innovations (T lower block triangular built recursively).
    lower = np.zeros((size, size))
    for k in range(n):
        lower[k * order:(k + 1) * order, k * order:(k + 1) * order] = np.eye(order)
        for j in range(k):
            f, _ = model(order, times[k] - times[j])
            lower[k * order:(k + 1) * order, j * order:(j + 1) * order] = f
    prior = lower @ noise_cov @ lower.T
    h = np.zeros((n - 1, size))
    for k in range(1, n):
        h[k - 1, k * order] = 1.0
    s = h @ prior @ h.T + noise**2 * np.eye(n - 1)
    gain = prior @ h.T @ np.linalg.inv(s)
    last = slice((n - 1) * order, n * order)
    for axis in range(3):
        m0 = np.zeros(order)
        m0[0] = z[0, axis]
        prior_mean = (lower @ np.concatenate([m0, np.zeros(size - order)]))
        mean = prior_mean + gain @ (z[1:, axis] - h @ prior_mean)
        state = [position_filter.x, position_filter.y, position_filter.z][axis]
        velocity = [position_filter.vx, position_filter.vy, position_filter.vz][axis]
        np.testing.assert_allclose([state, velocity], mean[last][:2], rtol=1e-9, atol=1e-12)
    posterior = prior - gain @ h @ prior
    np.testing.assert_allclose(position_filter.covariance.matrix(), posterior[last, last], rtol=1e-8, atol=1e-14)


@pytest.mark.parametrize("order", [2, 3])
def test_a_million_updates_keep_the_covariance_positive_definite_and_accurate(order):
    rng = np.random.default_rng(11)
    steps = rng.choice([1e-6, 0.001, 0.0083, 0.016, 2.0], size=1_000_000, p=[0.05, 0.2, 0.5, 0.249, 0.001])
    covariance = KinematicCovariance(order, 30.0, 1e-8, (1e-8, 1.0, 100.0)[:order])
    smallest = np.inf
    for dt in steps.tolist():
        covariance.predict(dt)
        covariance.update()
        smallest = min(smallest, min(covariance.diagonal_factor()))
    assert smallest > 0.0
    assert np.all(np.linalg.eigvalsh(covariance.matrix()) > 0.0)
    # Nothing accumulated: at a steady rate the filter settles on the Riccati equation's solution.
    dt = 1 / 120
    for _ in range(5000):
        covariance.predict(dt)
        covariance.update()
    f, q = model(order, dt)
    h = np.eye(order)[:1]
    prior = scipy.linalg.solve_discrete_are(f.T, h.T, 30.0 * q, np.array([[1e-8]]))
    posterior = prior - prior @ h.T @ h @ prior / (h @ prior @ h.T + 1e-8)
    np.testing.assert_allclose(covariance.matrix(), posterior, rtol=1e-6)


components = st.floats(-1.0, 1.0, allow_nan=False)
unit = st.tuples(components, components, components, components).filter(lambda q: np.linalg.norm(q) > 0.1).map(
    lambda q: tuple(quat.normalise(q).tolist())
)
vectors = st.tuples(*[st.floats(-4.0, 4.0, allow_nan=False)] * 3)


@laws
@given(a=unit, b=unit)
def test_scalar_multiply_is_the_hamilton_product(a, b):
    np.testing.assert_allclose(squat.multiply(a, b), quat.multiply(a, b), atol=1e-15)


@laws
@given(r=vectors, q=unit)
def test_scalar_rotated_by_is_the_rotation_vector_applied_in_the_world_frame(r, q):
    expected = quat.multiply(quat.from_rotation_vector(r), q)
    assert quat.angle_between(squat.rotated_by(*r, q), expected) < 1e-12


@laws
@given(a=unit, b=unit)
def test_scalar_rotation_vector_between_takes_the_short_way(a, b):
    r = np.array(squat.rotation_vector_between(a, b))
    assert np.linalg.norm(r) <= np.pi + 1e-12
    assert quat.angle_between(quat.multiply(quat.from_rotation_vector(r), a), b) < 1e-9
    np.testing.assert_allclose(squat.rotation_vector_between(a, tuple(-v for v in b)), r, atol=1e-12)


@laws
@given(a=unit, b=unit, u=st.floats(-3.0, 5.0))
def test_scalar_slerp_is_quaternion_slerp(a, b, u):
    assert quat.angle_between(squat.slerp(a, b, u), quat.slerp(a, b, u)) < 1e-9
