"""Pose and PoseSample: validated, immutable plain values."""

import math

import numpy as np
import pytest

from predictors import Pose, PoseSample, PredictorError

UNIT_Q = [0.5, 0.5, 0.5, 0.5]


def test_keyword_construction_from_sequences():
    pose = Pose(t=1.5, position=[1, 2, 3], orientation=(1, 0, 0, 0))
    assert pose.t == 1.5 and isinstance(pose.t, float)
    assert pose.position.dtype == np.float64 and pose.position.tolist() == [1.0, 2.0, 3.0]
    assert pose.orientation.dtype == np.float64 and pose.orientation.tolist() == [1.0, 0.0, 0.0, 0.0]


def test_keyword_construction_from_arrays():
    sample = PoseSample(
        t_sensor=np.float64(2.0),
        t_arrival=np.float32(2.5),
        position=np.array([0.1, 0.2, 0.3], dtype=np.float32),
        orientation=np.array(UNIT_Q),
    )
    assert (sample.t_sensor, sample.t_arrival) == (2.0, 2.5)
    assert sample.position.dtype == np.float64
    np.testing.assert_allclose(sample.position, [0.1, 0.2, 0.3], rtol=1e-7)
    np.testing.assert_array_equal(sample.orientation, UNIT_Q)


def test_sample_pose_is_stamped_with_sensor_time():
    pose = PoseSample(t_sensor=1.0, t_arrival=1.01, position=[1, 2, 3], orientation=UNIT_Q).pose()
    assert isinstance(pose, Pose) and pose.t == 1.0
    assert pose.position.tolist() == [1.0, 2.0, 3.0]


def test_nearly_unit_orientation_is_normalised_exactly():
    q = np.array(UNIT_Q) * (1 + 5e-7)
    pose = Pose(t=0.0, position=[0, 0, 0], orientation=q)
    assert np.linalg.norm(pose.orientation) == pytest.approx(1.0, abs=1e-15)


def test_arrays_are_private_read_only_copies():
    position, orientation = np.array([1.0, 2.0, 3.0]), np.array([1.0, 0.0, 0.0, 0.0])
    pose = Pose(t=0.0, position=position, orientation=orientation)
    position[0] = orientation[0] = 99.0
    assert pose.position[0] == 1.0 and pose.orientation[0] == 1.0
    with pytest.raises(ValueError):
        pose.position[0] = 5.0
    with pytest.raises(ValueError):
        pose.orientation[0] = 5.0


@pytest.mark.parametrize("position", [[1, 2], [1, 2, 3, 4], [[1, 2, 3]], 1.0])
def test_wrong_position_shape_is_rejected(position):
    with pytest.raises(PredictorError, match=r"position must have shape \(3,\)"):
        Pose(t=0.0, position=position, orientation=UNIT_Q)


@pytest.mark.parametrize("orientation", [[1, 0, 0], [[1, 0, 0, 0]], [1, 0, 0, 0, 0]])
def test_wrong_orientation_shape_is_rejected(orientation):
    with pytest.raises(PredictorError, match="quaternion, got shape"):
        PoseSample(t_sensor=0.0, t_arrival=0.0, position=[0, 0, 0], orientation=orientation)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_values_are_rejected(bad):
    with pytest.raises(PredictorError, match="position must be finite"):
        Pose(t=0.0, position=[0.0, bad, 0.0], orientation=UNIT_Q)
    with pytest.raises(PredictorError, match="orientation must be finite"):
        Pose(t=0.0, position=[0, 0, 0], orientation=[bad, 0.0, 0.0, 0.0])
    with pytest.raises(PredictorError, match="Pose.t must be a finite time"):
        Pose(t=bad, position=[0, 0, 0], orientation=UNIT_Q)
    with pytest.raises(PredictorError, match="t_arrival must be a finite time"):
        PoseSample(t_sensor=0.0, t_arrival=bad, position=[0, 0, 0], orientation=UNIT_Q)


@pytest.mark.parametrize("orientation", [[2, 0, 0, 0], [0, 0, 0, 0], [0.5, 0.5, 0.5, 0.4999]])
def test_non_unit_orientation_is_rejected(orientation):
    with pytest.raises(PredictorError, match="unit quaternion.*normalise it first"):
        Pose(t=0.0, position=[0, 0, 0], orientation=orientation)


@pytest.mark.parametrize(
    "fields",
    [
        {"t": "soon", "position": [0, 0, 0], "orientation": UNIT_Q},
        {"t": 0.0, "position": ["a", 0, 0], "orientation": UNIT_Q},
        {"t": 0.0, "position": [0, 0, 0], "orientation": [1, [0, 0], 0]},
    ],
)
def test_non_numeric_values_are_rejected(fields):
    with pytest.raises(PredictorError):
        Pose(**fields)


def test_predictor_error_is_a_value_error():
    assert issubclass(PredictorError, ValueError)
