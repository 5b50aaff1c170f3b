"""`split` predicts position exactly as `adaptive` and orientation exactly as the damped `kalman-cv`,
at 30 Hz and 1 kHz, through faults; and a million samples stay exact and finite."""

from types import SimpleNamespace

import numpy as np
import pytest

from predictors import PoseSample, PredictorError, make
from predictors import quaternion as quat
from predictors import scalar_quaternion as squat
from predictors.stress import head_motion_truth, sampled, with_coloured_noise

Q0 = quat.normalise([0.9, 0.1, -0.3, 0.2])
OMEGA = np.array([0.5, -1.0, 0.3])
VELOCITY = np.array([0.4, -0.2, 0.05])
P0 = np.array([0.1, 1.5, -0.3])


@pytest.mark.parametrize("rate_hz", [30.0, 1000.0], ids=["30Hz", "1kHz"])
def test_each_part_is_predicted_as_its_own_predictor_would(rate_hz):
    truth = head_motion_truth(4.0, seed=5)
    stream = with_coloured_noise(sampled(truth, rate_hz, 0.1, seed=5), 0.0005, 0.1, 0.5, seed=5)
    split = make("split", angular_velocity_damping=6.0, margin=0.1)
    position, orientation = make("adaptive", margin=0.1), make("kalman-cv", angular_velocity_damping=6.0)
    for k, sample in enumerate(stream.samples()):
        flipped = PoseSample(sample.t_sensor, sample.t_arrival, sample.position, -sample.orientation if k % 3 else sample.orientation)
        for predictor in (split, position, orientation):
            predictor.update(flipped)
        if k % 7 == 0:
            t = sample.t_arrival + 0.05
            pose = split.predict(t)
            np.testing.assert_array_equal(pose.position, position.predict(t).position)
            np.testing.assert_allclose(pose.orientation, orientation.predict(t).orientation, rtol=0, atol=1e-15)


def test_the_default_damps_the_angular_velocity():
    assert make("split").angular_velocity_damping == 4.0


def test_errors_name_split():
    predictor = make("split")
    with pytest.raises(PredictorError, match="'split' has no sample yet"):
        predictor.predict(0.0)
    predictor.update(PoseSample(0.0, 0.0, P0, Q0))
    with pytest.raises(PredictorError, match="'split' was asked for time nan"):
        predictor.predict(float("nan"))


@pytest.mark.slow
def test_a_million_samples_stay_exact_and_finite():
    """A thousand seconds at 1000 Hz of noiseless constant-velocity motion, undamped: still exact."""
    predictor = make("split", angular_velocity_damping=0.0)
    q0 = tuple(Q0.tolist())
    (px, py, pz), (vx, vy, vz), (wx, wy, wz) = P0.tolist(), VELOCITY.tolist(), OMEGA.tolist()
    samples = 1_000_000
    for k in range(samples):
        t = 0.001 * k
        orientation = squat.rotated_by(wx * t, wy * t, wz * t, q0)
        predictor.update(SimpleNamespace(t_sensor=t, position=(px + vx * t, py + vy * t, pz + vz * t), orientation=orientation))
    t = 0.001 * (samples - 1)
    for horizon in (0.0, 0.02, 0.1):
        prediction = predictor.predict(t + horizon)
        truth = quat.multiply(quat.from_rotation_vector(OMEGA * (t + horizon)), Q0)
        np.testing.assert_allclose(prediction.position, P0 + VELOCITY * (t + horizon), rtol=0, atol=1e-6)
        assert quat.angle_between(prediction.orientation, truth) < 1e-6
