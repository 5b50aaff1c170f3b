"""Tuning with the JAX twins: the fitted parameters predict better than where they started."""

import math

import pytest

from predictors import evaluate
from predictors.synthetic import head_motion
from predictors.tuning import tune



@pytest.fixture(scope="module")
def traces():
    motion = head_motion(8.0, 60.0, seed=5).with_noise(0.002, math.radians(0.3), seed=5)
    return motion.split(0.5)


def test_tuning_kalman_cv_lowers_held_out_error_from_a_poor_start(traces):
    train, held_out = traces
    start = {"acceleration_noise": 0.01, "angular_acceleration_noise": 0.05}
    result = tune("kalman-cv", [train], 0.05, start, max_iterations=15)
    assert result.fitted == ("acceleration_noise", "angular_acceleration_noise")
    assert result.loss_after < 0.8 * result.loss_before
    before = evaluate("kalman-cv", held_out, [0.05], start, timing_repeats=1).at(50.0)
    after = evaluate("kalman-cv", held_out, [0.05], result.params, timing_repeats=1).at(50.0)
    assert after.angular_rms_deg < before.angular_rms_deg
    assert after.position_rms_mm < before.position_rms_mm


def test_tuning_an_untunable_predictor_is_a_clear_error(traces):
    from predictors import PredictorError

    with pytest.raises(PredictorError, match="cannot tune 'slerp'; tunable predictors: kalman-cv, kalman-ca, desp"):
        tune("slerp", [traces[0]], 0.05)
