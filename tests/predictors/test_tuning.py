"""Tuning with the JAX twins: the fitted parameters predict better than where they started, the
fitted damping is the motion's own, and auto's choice is fitted on a grid."""

import math
import os
import subprocess
import sys
from pathlib import Path

import jax
import numpy as np
import pytest
from scipy.signal import lfilter

from predictors import Trace, evaluate
from predictors import scalar_quaternion as squat
from predictors.registry import params_of
from predictors.synthetic import head_motion
from predictors.tuning import AUTO_GRIDS, AUTO_MARGIN_GRID, AUTO_MEMORY_GRID_S, tune


@pytest.fixture(scope="module")
def traces():
    motion = head_motion(8.0, 60.0, seed=5).with_noise(0.002, math.radians(0.3), seed=5)
    return motion.split(0.5)


def test_tuning_kalman_cv_lowers_held_out_error_from_a_poor_start(traces):
    train, held_out = traces
    start = {"acceleration_noise": 0.01, "angular_acceleration_noise": 0.05}
    result = tune("kalman-cv", [train], 0.05, start, max_iterations=15)
    assert result.fitted == ("acceleration_noise", "angular_acceleration_noise", "angular_velocity_damping")
    assert result.loss_after < 0.8 * result.loss_before
    before = evaluate("kalman-cv", held_out, [0.05], start, timing_repeats=1).at(50.0)
    after = evaluate("kalman-cv", held_out, [0.05], result.params, timing_repeats=1).at(50.0)
    assert after.angular_rms_deg < before.angular_rms_deg
    assert after.position_rms_mm < before.position_rms_mm


def test_importing_the_twins_and_tuning_leaves_jax_in_float32():
    code = "import predictors, predictors.jax_filters, predictors.tuning, jax; print(jax.config.jax_enable_x64)"
    environment = {k: v for k, v in os.environ.items() if k != "JAX_ENABLE_X64"}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=environment,
                          cwd=Path(__file__).resolve().parents[2])
    assert done.stdout.strip() == "False"


def test_tuning_computes_in_float64_whatever_the_callers_setting_and_restores_it(traces):
    train = traces[0]
    results = {}
    for caller in (False, True):
        with jax.enable_x64(caller):
            results[caller] = tune("desp", [train], 0.02, max_iterations=2)
            assert jax.config.jax_enable_x64 is caller
    assert results[False] == results[True]


def test_tuning_an_untunable_predictor_is_a_clear_error(traces):
    from predictors import PredictorError

    with pytest.raises(PredictorError, match="cannot tune 'slerp'; tunable predictors: kalman-cv, kalman-ca, desp"):
        tune("slerp", [traces[0]], 0.05)


TRUE_DAMPING = 5.0  # 1/s
NOISE = math.radians(0.05)


def slowing_turns(seconds: float, rate_hz: float, damping: float, speed_std: float, seed: int) -> Trace:
    """Orientation whose world angular velocity is an Ornstein-Uhlenbeck process, reverting to rest at
    `damping` (1/s) with a stationary spread of `speed_std` (rad/s) per axis: the motion the damped
    filter models. Integrated at 1 kHz with the exact discrete velocity step, sampled at rate_hz."""
    rng = np.random.default_rng(seed)
    step = 1e-3
    decay = math.exp(-damping * step)
    kicks = speed_std * math.sqrt(1.0 - decay * decay) * rng.standard_normal((int(seconds / step) + 1, 3))
    velocity = lfilter([1.0], [1.0, -decay], kicks, axis=0)
    q = squat.IDENTITY
    orientations = []
    for wx, wy, wz in velocity.tolist():
        orientations.append(q)
        q = squat.rotated_by(step * wx, step * wy, step * wz, q)
    t = np.arange(len(orientations)) * step
    fine = Trace.from_samples("slowing-turns", t, np.zeros((t.size, 3)), np.array(orientations))
    return fine.resampled(rate_hz)


@pytest.fixture(scope="module")
def slowing():
    motion = slowing_turns(16.0, 60.0, TRUE_DAMPING, 1.0, seed=1).with_noise(0.0, NOISE, seed=1)
    train, held_out = motion.split(0.5)
    return tune("auto", [train], 0.05, {"orientation_noise": NOISE}, max_iterations=20), held_out


def test_tuning_recovers_the_damping_of_turns_that_slow_down(slowing):
    result, _ = slowing
    assert result.params["angular_velocity_damping"] == pytest.approx(TRUE_DAMPING, rel=0.35)


def test_tuning_auto_fits_its_filters_then_picks_memory_and_margin_from_the_grid(slowing):
    result, held_out = slowing
    assert result.fitted == ("angular_acceleration_noise", "angular_velocity_damping", "memory", "margin")
    assert result.params["memory"] in AUTO_MEMORY_GRID_S and result.params["margin"] in AUTO_MARGIN_GRID
    assert result.loss_after < result.loss_before
    tuned, start, slerp = (
        evaluate(name, held_out, [0.05], params, timing_repeats=1).at(50.0).angular_rms_deg
        for name, params in (("auto", result.params), ("auto", {"orientation_noise": NOISE}), ("slerp", {}))
    )
    assert tuned < start and tuned < slerp


def test_auto_fits_as_kalman_cv_what_they_share_and_the_rest_of_its_trainables_on_the_grid():
    kalman, auto = params_of("kalman-cv"), {p.name for p in params_of("auto").trainable}
    assert auto - set(kalman.names) == set(AUTO_GRIDS)
    assert auto & set(kalman.names) == {p.name for p in kalman.trainable}
