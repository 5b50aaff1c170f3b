"""predictors.quaternion: hard numerical cases, algebraic laws, and agreement with scipy."""

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation, Slerp

from predictors import PredictorError
from predictors import quaternion as quat

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
Z_AXIS = np.array([0.0, 0.0, 1.0])
EXTRAPOLATIONS = [-5.0, -1.0, 0.0, 0.25, 0.5, 1.0, 2.0, 10.0]

laws = settings(deadline=None, max_examples=60, derandomize=True)

components = st.floats(-1.0, 1.0, allow_nan=False)
unit_quaternions = (
    st.tuples(components, components, components, components)
    .map(np.array)
    .filter(lambda q: np.linalg.norm(q) > 0.1)
    .map(lambda q: q / np.linalg.norm(q))
)
vectors = st.tuples(*[st.floats(-10.0, 10.0, allow_nan=False)] * 3).map(np.array)
unit_axes = vectors.filter(lambda v: np.linalg.norm(v) > 0.1).map(lambda v: v / np.linalg.norm(v))
reals = st.floats(-10.0, 10.0, allow_nan=False)


def random_unit_quaternions(n: int, seed: int) -> np.ndarray:
    q = np.random.default_rng(seed).normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def assert_same_rotation(actual: np.ndarray, expected: np.ndarray, tol: float) -> None:
    assert np.all(quat.angle_between(actual, expected) <= tol), quat.angle_between(actual, expected)


def to_scipy(q: np.ndarray) -> Rotation:
    """scipy stores quaternions scalar-last (x, y, z, w); ours are (w, x, y, z)."""
    return Rotation.from_quat(np.roll(q, -1, axis=-1))


def from_scipy(rotation: Rotation) -> np.ndarray:
    return np.roll(rotation.as_quat(), 1, axis=-1)


# --- hard cases -----------------------------------------------------------------------------


def test_slerp_of_identical_inputs_stays_put_for_any_u():
    q = random_unit_quaternions(1, seed=1)[0]
    result = quat.slerp(q, q, np.array(EXTRAPOLATIONS))
    assert np.all(np.isfinite(result))
    np.testing.assert_allclose(result, np.broadcast_to(q, result.shape), atol=1e-15)


def test_inputs_1e9_rad_apart_keep_their_angle():
    q0 = random_unit_quaternions(1, seed=2)[0]
    q1 = quat.multiply(q0, quat.from_axis_angle([0.3, -0.4, 0.5], 1e-9))
    # An arccos of the dot product would report 0 here; the atan2 form keeps the angle.
    assert quat.angle_between(q0, q1) == pytest.approx(1e-9, rel=1e-6)
    us = np.array(EXTRAPOLATIONS)
    result = quat.slerp(q0, q1, us)
    assert np.all(np.isfinite(result))
    np.testing.assert_allclose(quat.angle_between(q0, result), np.abs(us) * 1e-9, rtol=1e-6, atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(result, axis=-1), 1.0, atol=1e-15)


def test_tiny_rotation_vectors_round_trip_without_losing_digits():
    r = np.array([1e-9, -2e-9, 3e-12])
    np.testing.assert_allclose(quat.to_rotation_vector(quat.from_rotation_vector(r)), r, rtol=1e-12)
    np.testing.assert_allclose(quat.log(quat.exp(r)), r, rtol=1e-12)
    np.testing.assert_array_equal(quat.exp(np.zeros(3)), IDENTITY)
    np.testing.assert_array_equal(quat.log(IDENTITY), np.zeros(3))


def test_antipodal_inputs_are_no_motion():
    q = random_unit_quaternions(1, seed=3)[0]
    result = quat.slerp(q, -q, np.array(EXTRAPOLATIONS))
    np.testing.assert_allclose(result, np.broadcast_to(q, result.shape), atol=1e-15)
    assert quat.angle_between(q, -q) == 0.0
    np.testing.assert_allclose(quat.to_rotation_vector(-q), quat.to_rotation_vector(q), atol=1e-15)


def test_log_of_a_full_turn_is_pi_about_some_axis():
    np.testing.assert_array_equal(quat.log(-IDENTITY), [math.pi, 0.0, 0.0])
    np.testing.assert_allclose(quat.exp(quat.log(-IDENTITY)), -IDENTITY, atol=1e-15)
    assert quat.to_rotation_vector(-IDENTITY).tolist() == [0.0, 0.0, 0.0]


@pytest.mark.parametrize("offset", [1e-7, 0.0, -1e-7])
def test_rotation_near_180_degrees_takes_the_short_way(offset):
    angle = math.pi - offset
    q1 = quat.from_axis_angle(Z_AXIS, angle)
    # Past 180 degrees about +z is short of 180 degrees about -z.
    short_angle = abs(angle) if angle <= math.pi else 2 * math.pi - angle
    short_axis = Z_AXIS if angle <= math.pi else -Z_AXIS
    assert quat.angle_between(IDENTITY, q1) == pytest.approx(short_angle, abs=1e-12)
    np.testing.assert_allclose(quat.to_rotation_vector(q1), short_axis * short_angle, atol=1e-12)
    for u in [0.5, 2.0]:
        expected = quat.from_axis_angle(short_axis, u * short_angle)
        assert_same_rotation(quat.slerp(IDENTITY, q1, u), expected, tol=1e-12)
    assert_same_rotation(quat.from_matrix(quat.to_matrix(q1)), q1, tol=1e-12)


@pytest.mark.parametrize("u", [-5.0, 10.0])
@pytest.mark.parametrize("frame", ["body", "world"])
def test_extrapolation_far_past_the_samples_matches_constant_rate_rotation(u, frame):
    """Samples of a constant-rate rotation at t = 0 and t = h, extrapolated to t = u h."""
    base = random_unit_quaternions(1, seed=4)[0]
    axis = np.array([0.2, -0.7, 0.4])
    rate, h = 2.5, 0.1  # rad/s, s: 0.25 rad between the samples

    def truth(t: float) -> np.ndarray:
        step = quat.from_axis_angle(axis, rate * t)
        return quat.multiply(base, step) if frame == "body" else quat.multiply(step, base)

    result = quat.slerp(truth(0.0), truth(h), u)
    assert_same_rotation(result, truth(u * h), tol=1e-12)
    assert quat.angle_between(truth(0.0), result) == pytest.approx(abs(u) * rate * h, abs=1e-12)
    assert np.linalg.norm(result) == pytest.approx(1.0, abs=1e-15)


def test_unnormalised_input_is_normalised():
    q0, q1 = random_unit_quaternions(2, seed=5)
    v = np.array([0.3, -1.2, 2.0])
    np.testing.assert_allclose(quat.slerp(3.7 * q0, 0.01 * q1, 2.5), quat.slerp(q0, q1, 2.5), atol=1e-14)
    np.testing.assert_allclose(quat.rotate(3.7 * q0, v), quat.rotate(q0, v), atol=1e-14)
    np.testing.assert_allclose(quat.to_matrix(0.2 * q0), quat.to_matrix(q0), atol=1e-14)
    np.testing.assert_allclose(quat.log(5.0 * q0), quat.log(q0), atol=1e-14)
    assert quat.angle_between(2.0 * q0, 0.5 * q1) == pytest.approx(quat.angle_between(q0, q1), abs=1e-14)
    np.testing.assert_allclose(np.linalg.norm(quat.normalise(3.7 * q0)), 1.0, atol=1e-15)


def test_zero_quaternion_or_axis_is_an_error():
    with pytest.raises(PredictorError, match="zero norm"):
        quat.normalise(np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]]))
    with pytest.raises(PredictorError, match="axis"):
        quat.from_axis_angle(np.zeros(3), 1.0)


@pytest.mark.parametrize(
    "call",
    [
        lambda: quat.multiply(np.ones(3), IDENTITY),
        lambda: quat.exp(np.ones(4)),
        lambda: quat.rotate(IDENTITY, np.ones(4)),
        lambda: quat.from_matrix(np.eye(4)),
        lambda: quat.normalise(1.0),
    ],
)
def test_wrong_shapes_are_an_error(call):
    with pytest.raises(PredictorError, match="shape"):
        call()


def test_great_circle_tangent_is_unit_and_orthogonal():
    q0, q1 = random_unit_quaternions(2, seed=18)
    half_angle, tangent = quat.great_circle(q0, q1)
    assert half_angle == pytest.approx(quat.angle_between(q0, q1) / 2, abs=1e-15)
    assert np.linalg.norm(tangent) == pytest.approx(1.0, abs=1e-15)
    assert np.dot(tangent, q0) == pytest.approx(0.0, abs=1e-15)
    for same in (q0, -q0):
        assert quat.great_circle(q0, same)[0] <= 1e-15
    assert quat.great_circle(IDENTITY, IDENTITY)[0] == 0.0
    assert not quat.great_circle(IDENTITY, IDENTITY)[1].any()


def test_functions_broadcast_over_leading_axes():
    q = random_unit_quaternions(6, seed=6).reshape(2, 3, 4)
    assert quat.multiply(q, IDENTITY).shape == (2, 3, 4)
    assert quat.rotate(q, np.ones(3)).shape == (2, 3, 3)
    assert quat.to_matrix(q).shape == (2, 3, 3, 3)
    assert quat.from_matrix(quat.to_matrix(q)).shape == (2, 3, 4)
    assert quat.angle_between(q, IDENTITY).shape == (2, 3)
    assert quat.slerp(q[0], q[1], np.zeros((5, 1))).shape == (5, 3, 4)
    axis, angle = quat.to_axis_angle(q)
    assert axis.shape == (2, 3, 3) and angle.shape == (2, 3)


def test_axis_angle_round_trip_and_identity_axis():
    axis, angle = quat.to_axis_angle(quat.from_axis_angle([0.0, 2.0, 0.0], -0.5))
    np.testing.assert_allclose(axis, [0.0, -1.0, 0.0], atol=1e-15)
    assert angle == pytest.approx(0.5, abs=1e-15)
    axis, angle = quat.to_axis_angle(IDENTITY)
    assert axis.tolist() == [1.0, 0.0, 0.0] and angle == 0.0


# --- laws -----------------------------------------------------------------------------------


@laws
@given(unit_quaternions, unit_quaternions)
def test_multiply_preserves_unit_norm(p, q):
    assert np.linalg.norm(quat.multiply(p, q)) == pytest.approx(1.0, abs=1e-14)


@laws
@given(unit_quaternions, unit_quaternions, reals)
def test_slerp_preserves_unit_norm(q0, q1, u):
    assert np.linalg.norm(quat.slerp(q0, q1, u)) == pytest.approx(1.0, abs=1e-14)


@laws
@given(st.tuples(*[st.floats(-100.0, 100.0, allow_nan=False)] * 3).map(np.array))
def test_exp_is_unit_norm(v):
    assert np.linalg.norm(quat.exp(v)) == pytest.approx(1.0, abs=1e-14)


@laws
@given(unit_quaternions, vectors)
@example(q=np.array([0.0, 0.0, 0.0, 1.0]), v=np.zeros(3))  # a half turn: w == 0 for q and -q
def test_q_and_minus_q_rotate_vectors_identically(q, v):
    np.testing.assert_allclose(quat.rotate(-q, v), quat.rotate(q, v), atol=1e-12)
    np.testing.assert_allclose(quat.to_matrix(-q), quat.to_matrix(q), atol=1e-15)
    np.testing.assert_allclose(quat.to_rotation_vector(-q), quat.to_rotation_vector(q), atol=1e-12)
    np.testing.assert_array_equal(quat.canonical(-q), quat.canonical(q))


@laws
@given(unit_quaternions, unit_quaternions)
def test_slerp_endpoints_are_the_inputs_up_to_sign(q0, q1):
    np.testing.assert_allclose(quat.slerp(q0, q1, 0.0), q0, atol=1e-15)
    assert quat.angle_between(quat.slerp(q0, q1, 1.0), q1) <= 1e-12


@laws
@given(unit_quaternions, unit_quaternions, reals, reals)
def test_slerp_moves_at_constant_rate(q0, q1, u, v):
    """Angle between the points at u and v is |u - v| times the angle from q0 to q1, mod 2 pi."""
    step = quat.angle_between(q0, q1)
    travelled = abs(u - v) * step % (2 * math.pi)
    expected = min(travelled, 2 * math.pi - travelled)
    actual = quat.angle_between(quat.slerp(q0, q1, u), quat.slerp(q0, q1, v))
    assert actual == pytest.approx(expected, abs=1e-10)


@laws
@given(unit_quaternions)
@example(q=np.array([-1.0, 0.0, 0.0, 2.27332273e-162]))  # |vector part|^2 underflows
@example(q=np.array([1.0, 0.0, 0.0, 2.27332273e-162]))
def test_exp_of_log_is_the_same_quaternion(q):
    np.testing.assert_allclose(quat.exp(quat.log(q)), q, atol=1e-14)


@laws
@given(unit_axes, st.floats(0.0, 3.1, allow_nan=False))
def test_log_of_exp_and_rotation_vector_round_trip(axis, length):
    v = axis * length
    np.testing.assert_allclose(quat.log(quat.exp(v)), v, atol=1e-12)
    np.testing.assert_allclose(quat.to_rotation_vector(quat.from_rotation_vector(v)), v, atol=1e-12)


@laws
@given(unit_quaternions, unit_quaternions, vectors)
def test_rotating_by_a_product_is_rotating_twice(p, q, v):
    np.testing.assert_allclose(
        quat.rotate(quat.multiply(p, q), v), quat.rotate(p, quat.rotate(q, v)), atol=1e-12
    )
    np.testing.assert_allclose(quat.to_matrix(q) @ v, quat.rotate(q, v), atol=1e-12)


@laws
@given(unit_quaternions)
def test_matrix_round_trip(q):
    result = quat.from_matrix(quat.to_matrix(q))
    assert_same_rotation(result, q, tol=1e-12)
    assert result[0] >= 0.0


@laws
@given(unit_quaternions, unit_quaternions)
def test_angle_between_is_symmetric_sign_invariant_and_in_range(q0, q1):
    angle = quat.angle_between(q0, q1)
    assert 0.0 <= angle <= math.pi
    assert quat.angle_between(q1, q0) == pytest.approx(angle, abs=1e-14)
    assert quat.angle_between(-q0, q1) == pytest.approx(angle, abs=1e-14)


# --- agreement with scipy (scalar-last storage) ----------------------------------------------


def test_multiply_matches_scipy_composition():
    p, q = random_unit_quaternions(200, seed=7), random_unit_quaternions(200, seed=8)
    assert_same_rotation(quat.multiply(p, q), from_scipy(to_scipy(p) * to_scipy(q)), tol=1e-12)


def test_matrices_match_scipy():
    q = random_unit_quaternions(200, seed=9)
    np.testing.assert_allclose(quat.to_matrix(q), to_scipy(q).as_matrix(), atol=1e-14)
    assert_same_rotation(quat.from_matrix(to_scipy(q).as_matrix()), q, tol=1e-12)


def test_rotation_vectors_match_scipy():
    q = random_unit_quaternions(200, seed=10)
    np.testing.assert_allclose(quat.to_rotation_vector(q), to_scipy(q).as_rotvec(), atol=1e-12)
    r = np.random.default_rng(11).uniform(-2.0, 2.0, size=(200, 3))
    assert_same_rotation(quat.from_rotation_vector(r), from_scipy(Rotation.from_rotvec(r)), tol=1e-12)


def test_rotate_matches_scipy():
    q = random_unit_quaternions(200, seed=12)
    v = np.random.default_rng(13).normal(size=(200, 3))
    np.testing.assert_allclose(quat.rotate(q, v), to_scipy(q).apply(v), atol=1e-12)


def test_angle_between_matches_scipy():
    q0, q1 = random_unit_quaternions(200, seed=14), random_unit_quaternions(200, seed=15)
    expected = (to_scipy(q0).inv() * to_scipy(q1)).magnitude()
    np.testing.assert_allclose(quat.angle_between(q0, q1), expected, atol=1e-12)


def test_slerp_within_0_1_matches_scipy():
    q0, q1 = random_unit_quaternions(40, seed=16), random_unit_quaternions(40, seed=17)
    us = np.linspace(0.0, 1.0, 7)
    for a, b in zip(q0, q1):
        expected = from_scipy(Slerp([0.0, 1.0], to_scipy(np.stack([a, b])))(us))
        assert_same_rotation(quat.slerp(a, b, us), expected, tol=1e-12)
