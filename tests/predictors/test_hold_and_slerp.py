"""The hold-last and slerp-extrapolation predictors against exact motion and awkward sample streams."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from predictors import Pose, PoseSample, PredictorError, make, names
from predictors import quaternion as quat

laws = settings(deadline=None, max_examples=60, derandomize=True)

TRANSPORT_DELAY = 0.002  # s; predictors must ignore it and use sensor time


def sample(t: float, position, orientation) -> PoseSample:
    return PoseSample(t_sensor=t, t_arrival=t + TRANSPORT_DELAY, position=position, orientation=orientation)


class ConstantMotion:
    """Constant linear velocity (m/s) and constant angular velocity (rad/s) about a fixed axis."""

    def __init__(self, position, velocity, orientation, axis, rate, world_frame=False):
        self.position, self.velocity = np.asarray(position, float), np.asarray(velocity, float)
        self.orientation, self.axis, self.rate = np.asarray(orientation, float), axis, rate
        self.world_frame = world_frame

    def pose(self, t: float) -> Pose:
        turn = quat.from_axis_angle(self.axis, self.rate * t)
        if self.world_frame:
            orientation = quat.multiply(turn, self.orientation)
        else:
            orientation = quat.multiply(self.orientation, turn)
        return Pose(t, self.position + self.velocity * t, orientation)

    def sample(self, t: float) -> PoseSample:
        pose = self.pose(t)
        return sample(t, pose.position, pose.orientation)


MOTION = ConstantMotion(
    position=[0.1, 1.5, -0.3],
    velocity=[0.4, -0.2, 0.05],
    orientation=quat.normalise([0.9, 0.1, -0.3, 0.2]),
    axis=[0, 1, 1],
    rate=1.5,
)


def assert_pose_close(actual: Pose, expected: Pose, tol: float = 1e-12) -> None:
    assert actual.t == expected.t
    np.testing.assert_allclose(actual.position, expected.position, rtol=0, atol=tol)
    assert quat.angle_between(actual.orientation, expected.orientation) <= tol


def assert_pose_equal(actual: Pose, t: float, expected: Pose) -> None:
    """actual is expected's pose, bit for bit, stamped with time t."""
    assert actual.t == t
    np.testing.assert_array_equal(actual.position, expected.position)
    np.testing.assert_array_equal(actual.orientation, expected.orientation)


def fed(name: str, *samples: PoseSample, **params) -> object:
    predictor = make(name, **params)
    for s in samples:
        predictor.update(s)
    return predictor


# --- both predictors ------------------------------------------------------------------------


@pytest.mark.parametrize("name", names())
def test_predict_before_any_sample_is_a_clear_error(name):
    with pytest.raises(PredictorError, match="no sample yet; call update"):
        make(name).predict(0.0)


@pytest.mark.parametrize("name", names())
def test_reset_forgets_every_sample(name):
    predictor = fed(name, MOTION.sample(0.0), MOTION.sample(0.01))
    predictor.reset()
    with pytest.raises(PredictorError, match="no sample yet"):
        predictor.predict(0.02)
    predictor.update(MOTION.sample(1.0))
    assert_pose_close(predictor.predict(1.0), MOTION.pose(1.0))


@pytest.mark.parametrize("name", names())
@pytest.mark.parametrize("t", [math.nan, math.inf, "now"])
def test_non_finite_prediction_time_is_an_error(name, t):
    with pytest.raises(PredictorError, match="finite time"):
        fed(name, MOTION.sample(0.0), MOTION.sample(0.01)).predict(t)


@pytest.mark.parametrize("name", names())
def test_a_single_sample_is_held(name):
    predictor = fed(name, MOTION.sample(2.0))
    for t in [1.0, 2.0, 2.5]:
        assert_pose_equal(predictor.predict(t), t, MOTION.pose(2.0))


# --- hold -----------------------------------------------------------------------------------


def test_hold_returns_the_newest_pose_stamped_with_the_asked_time():
    predictor = fed("hold", MOTION.sample(0.0), MOTION.sample(0.01), MOTION.sample(0.02))
    assert_pose_equal(predictor.predict(0.05), 0.05, MOTION.pose(0.02))


def test_hold_ignores_out_of_order_samples_and_takes_a_repeated_time():
    predictor = fed("hold", MOTION.sample(0.02), MOTION.sample(0.01))
    assert_pose_equal(predictor.predict(0.03), 0.03, MOTION.pose(0.02))
    predictor.update(sample(0.02, [9.0, 9.0, 9.0], [1, 0, 0, 0]))
    assert predictor.predict(0.03).position.tolist() == [9.0, 9.0, 9.0]


# --- slerp: exact on constant motion ---------------------------------------------------------


components = st.floats(-1.0, 1.0, allow_nan=False)
orientations = (
    st.tuples(components, components, components, components)
    .filter(lambda q: np.linalg.norm(q) > 0.1)
    .map(quat.normalise)
)
axes = st.tuples(components, components, components).filter(lambda v: np.linalg.norm(v) > 0.1)
triples = st.tuples(*[st.floats(-5.0, 5.0, allow_nan=False)] * 3)


@laws
@given(
    position=triples,
    velocity=triples,
    orientation=orientations,
    axis=axes,
    rate=st.floats(-30.0, 30.0),  # rad/s: at most 1.5 rad between samples, short of pi
    world_frame=st.booleans(),
    t0=st.floats(0.0, 10.0),
    interval=st.floats(1e-3, 0.05),
    horizon=st.floats(-0.1, 0.5),
)
def test_slerp_predicts_constant_motion_exactly(
    position, velocity, orientation, axis, rate, world_frame, t0, interval, horizon
):
    motion = ConstantMotion(position, velocity, orientation, axis, rate, world_frame)
    t1 = t0 + interval
    prediction = fed("slerp", motion.sample(t0), motion.sample(t1)).predict(t1 + horizon)
    assert_pose_close(prediction, motion.pose(t1 + horizon), tol=1e-9)


@laws
@given(
    q0=orientations,
    q1=orientations,
    t0=st.floats(-5.0, 5.0),
    interval=st.floats(1e-3, 1.0),
    u=st.floats(-5.0, 10.0),
)
def test_slerp_orientation_is_quaternion_slerp_with_u_from_sensor_times(q0, q1, t0, interval, u):
    t1 = t0 + interval
    t = t0 + u * (t1 - t0)
    prediction = fed("slerp", sample(t0, [0, 0, 0], q0), sample(t1, [0, 0, 0], q1)).predict(t)
    assert quat.angle_between(prediction.orientation, quat.slerp(q0, q1, u)) <= 1e-9


def test_slerp_follows_a_stream_of_samples_predicting_between_updates():
    predictor = fed("slerp", MOTION.sample(0.0))
    for k in range(1, 6):
        predictor.update(MOTION.sample(0.01 * k))
        for horizon in [0.0, 0.016, 0.1]:
            assert_pose_close(predictor.predict(0.01 * k + horizon), MOTION.pose(0.01 * k + horizon))


def test_slerp_at_the_newest_sample_time_is_that_sample():
    predictor = fed("slerp", MOTION.sample(0.0), MOTION.sample(0.01))
    assert_pose_equal(predictor.predict(0.01), 0.01, MOTION.pose(0.01))


def test_slerp_answers_times_before_the_newest_sample():
    predictor = fed("slerp", MOTION.sample(0.0), MOTION.sample(0.01))
    for t in [-1.0, 0.0, 0.005, 0.0099]:
        prediction = predictor.predict(t)
        assert np.all(np.isfinite(prediction.position)) and np.all(np.isfinite(prediction.orientation))
        assert_pose_close(prediction, MOTION.pose(t))


# --- slerp: awkward sample streams -----------------------------------------------------------


def test_slerp_duplicate_timestamp_replaces_the_newest_and_keeps_the_older():
    wrong = sample(0.01, [5.0, 5.0, 5.0], [0, 1, 0, 0])
    predictor = fed("slerp", MOTION.sample(0.0), wrong, MOTION.sample(0.01))
    assert_pose_close(predictor.predict(0.05), MOTION.pose(0.05))


def test_slerp_only_duplicate_timestamps_hold_the_latest_arrival():
    predictor = fed("slerp", sample(1.0, [0, 0, 0], [1, 0, 0, 0]), MOTION.sample(1.0), MOTION.sample(1.0))
    assert_pose_equal(predictor.predict(1.5), 1.5, MOTION.pose(1.0))


def test_slerp_samples_closer_than_min_interval_count_as_duplicates():
    wrong = sample(0.01, [5.0, 5.0, 5.0], [0, 1, 0, 0])
    predictor = fed("slerp", MOTION.sample(0.0), wrong, MOTION.sample(0.013), min_interval=0.005)
    assert_pose_close(predictor.predict(0.05), MOTION.pose(0.05))
    # With the default of 1 microsecond, a sample 1 ns later replaces the newest too.
    predictor = fed("slerp", MOTION.sample(0.0), wrong, MOTION.sample(0.01 + 1e-9))
    assert_pose_close(predictor.predict(0.05), MOTION.pose(0.05), tol=1e-9)


def test_slerp_ignores_out_of_order_samples():
    late = sample(0.005, [5.0, 5.0, 5.0], [0, 1, 0, 0])
    older_than_both = sample(-1.0, [5.0, 5.0, 5.0], [0, 0, 1, 0])
    predictor = fed("slerp", MOTION.sample(0.0), MOTION.sample(0.01), late, older_than_both)
    assert_pose_close(predictor.predict(0.05), MOTION.pose(0.05))


def test_slerp_sign_flipped_consecutive_samples_predict_the_short_way():
    """q then -q' for q' 0.01 rad from q: the same small motion as q then q', not a 360 degree spin."""
    motion = ConstantMotion([0, 0, 0], [0, 0, 0], quat.normalise([0.2, 0.9, -0.3, 0.1]), [1, 0, 0], 1.0)
    s0, s1 = motion.sample(0.0), motion.sample(0.01)
    flipped = sample(0.01, s1.position, -s1.orientation)
    predictor = fed("slerp", s0, flipped)
    for t in [0.0137, 0.05]:
        prediction = predictor.predict(t)
        assert_pose_close(prediction, motion.pose(t))
        turned = quat.angle_between(prediction.orientation, s1.orientation)
        assert turned == pytest.approx(t - 0.01, abs=1e-12)  # 1 rad/s for t - 0.01 s


def test_slerp_huge_sample_gap_stays_exact():
    slow = ConstantMotion([1, 2, 3], [1e-3, 0, -2e-3], quat.normalise([1, 2, 3, 4]), [1, -1, 0], 1e-3)
    predictor = fed("slerp", slow.sample(0.0), slow.sample(1000.0))
    assert_pose_close(predictor.predict(1500.0), slow.pose(1500.0), tol=1e-12)


def test_slerp_tiny_sample_gap_extrapolated_far_stays_exact():
    predictor = fed("slerp", MOTION.sample(0.0), MOTION.sample(1e-6))
    assert_pose_close(predictor.predict(2.0), MOTION.pose(2.0), tol=1e-8)
