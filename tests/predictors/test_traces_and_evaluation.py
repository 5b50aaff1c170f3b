"""Trace files, trace options, the synthetic head and the evaluation scores."""

import math
from pathlib import Path

import numpy as np
import pytest

from predictors import PredictorError, Trace, evaluate, read_params, read_trace, write_params, write_trace
from predictors import quaternion as quat
from predictors.synthetic import head_motion

EXCERPT = Path(__file__).resolve().parents[2] / "data" / "traces" / "hmd_orientation_user1_excerpt20s.csv"


def constant_motion(n: int = 200, rate: float = 100.0) -> Trace:
    t = np.arange(n) / rate
    position = np.array([0.1, 1.5, -0.3]) + np.outer(t, [0.4, -0.2, 0.05])
    orientation = quat.multiply(quat.from_rotation_vector(np.outer(t, [0.5, -1.0, 0.3])), [1.0, 0.0, 0.0, 0.0])
    return Trace.from_samples("constant", t, position, orientation)


def test_the_real_trace_excerpt_reads_with_its_sign_flips_and_repeats():
    trace = read_trace(EXCERPT)
    assert len(trace) > 1000 and trace.duration == pytest.approx(20.0, abs=0.1)
    assert np.all(trace.position == 0.0)
    assert np.any(np.sum(trace.orientation[1:] * trace.orientation[:-1], axis=1) < 0.0)
    np.testing.assert_allclose(np.linalg.norm(trace.orientation, axis=1), 1.0, atol=1e-15)


def test_write_then_read_gives_the_same_trace(tmp_path):
    trace = constant_motion().with_delay(0.004)
    write_trace(tmp_path / "t.csv", trace)
    back = read_trace(tmp_path / "t.csv")
    np.testing.assert_array_equal(back.t, trace.t)
    np.testing.assert_array_equal(back.t_arrival, trace.t_arrival)
    np.testing.assert_array_equal(back.position, trace.position)
    np.testing.assert_allclose(back.orientation, trace.orientation, atol=1e-15)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "is empty"),
        ("t,px,py,pz,qw,qx,qy\n", "lacks column"),
        ("t,px,py,pz,qw,qx,qy,qz\n0,0,0,0,1,0,0,zero\n", "must hold 8 numbers"),
        ("t,px,py,pz,qw,qx,qy,qz\n0,0,0,0,2,0,0,0\n", "unit norm"),
        ("t,px,py,pz,qw,qx,qy,qz\n", "no samples"),
    ],
)
def test_bad_trace_files_are_clear_errors(tmp_path, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(PredictorError, match=message):
        read_trace(path)


def test_a_missing_trace_file_is_a_clear_error(tmp_path):
    with pytest.raises(PredictorError, match="cannot read trace"):
        read_trace(tmp_path / "none.csv")


def test_noise_and_delay_change_the_samples_not_the_truth():
    clean = constant_motion()
    noisy = clean.with_noise(0.001, 0.002, seed=1).with_delay(0.01)
    np.testing.assert_array_equal(noisy.truth_position, clean.truth_position)
    assert np.std(noisy.position - clean.position) == pytest.approx(0.001, rel=0.1)
    np.testing.assert_allclose(noisy.t_arrival - noisy.t, 0.01)


def test_resampling_interpolates_the_truth():
    trace = constant_motion().resampled(37.0)
    assert np.allclose(np.diff(trace.t), 1.0 / 37.0)
    expected = np.array([0.1, 1.5, -0.3]) + np.outer(trace.t, [0.4, -0.2, 0.05])
    np.testing.assert_allclose(trace.position, expected, atol=1e-12)


def test_split_keeps_the_first_fraction_for_training():
    train, held_out = constant_motion().split(0.6)
    assert train.t.max() < held_out.t.min()
    assert len(train) == 120 and len(held_out) == 80


def test_slerp_scores_zero_error_on_constant_motion_and_hold_scores_the_motion():
    trace = constant_motion()
    slerp = evaluate("slerp", trace, [0.0, 0.05], timing_repeats=1)
    # Only the first prediction, from a single sample, misses: the 95th percentile is exact.
    assert slerp.at(50.0).position_p95_mm < 1e-9 and slerp.at(50.0).angular_p95_deg < 1e-6
    hold = evaluate("hold", trace, [0.05], timing_repeats=1)
    speed_mm = 1e3 * np.linalg.norm([0.4, -0.2, 0.05])
    assert hold.at(50.0).position_max_mm == pytest.approx(0.05 * speed_mm, rel=1e-9)
    assert hold.at(50.0).angular_max_deg == pytest.approx(math.degrees(0.05 * np.linalg.norm([0.5, -1.0, 0.3])), rel=1e-6)
    assert hold.at(50.0).count == 200 - 5  # the last 5 predictions lie past the end of the truth
    assert slerp.us_per_update > 0.0


def test_jitter_is_zero_for_straight_uniform_motion_and_not_for_noise():
    trace = constant_motion()
    assert evaluate("hold", trace, [0.02], timing_repeats=1).at(20.0).position_jitter_mm < 1e-9
    noisy = trace.with_noise(0.001, 0.0, seed=2)
    assert evaluate("hold", noisy, [0.02], timing_repeats=1).at(20.0).position_jitter_mm > 1.0


def test_synthetic_head_turns_at_up_to_300_deg_per_second_with_energy_below_2_hz():
    trace = head_motion(60.0, 120.0, seed=3)
    speed = np.degrees(quat.angle_between(trace.orientation[:-1], trace.orientation[1:]) * 120.0)
    assert 200.0 < speed.max() <= 310.0
    angles = quat.to_rotation_vector(quat.multiply(trace.orientation, quat.conjugate(trace.orientation[0])))
    spectrum = np.abs(np.fft.rfft(angles - angles.mean(axis=0), axis=0)) ** 2
    frequency = np.fft.rfftfreq(len(trace), 1.0 / 120.0)
    assert spectrum[frequency < 2.0].sum() / spectrum.sum() > 0.95
    still = speed < 5.0
    assert 0.2 < still.mean() < 0.9  # it stops, and it moves


def test_synthetic_head_is_deterministic_per_seed():
    np.testing.assert_array_equal(head_motion(5.0, seed=1).orientation, head_motion(5.0, seed=1).orientation)
    assert not np.array_equal(head_motion(5.0, seed=1).orientation, head_motion(5.0, seed=2).orientation)


def test_parameter_files_round_trip_and_reject_other_json(tmp_path):
    write_params(tmp_path / "p.json", "kalman-cv", {"acceleration_noise": 0.5}, horizon_ms=20.0)
    assert read_params(tmp_path / "p.json") == ("kalman-cv", {"acceleration_noise": 0.5})
    (tmp_path / "other.json").write_text("[1, 2]")
    with pytest.raises(PredictorError, match="not a predictor parameter file"):
        read_params(tmp_path / "other.json")


def test_order_faults_count_backward_steps_and_repeated_times_and_in_time_order_mends_them():
    t = np.array([0.0, 0.02, 0.01, 0.03, 0.03, 0.04])
    position = np.outer(np.arange(6.0), [1.0, 0.0, 0.0])
    trace = Trace.from_samples("faulty", t, position, np.tile([1.0, 0.0, 0.0, 0.0], (6, 1)), t_arrival=t + 0.5)
    assert trace.order_faults() == (1, 1)
    mended = trace.in_time_order()
    assert mended.order_faults() == (0, 0)
    np.testing.assert_array_equal(mended.t, [0.0, 0.01, 0.02, 0.03, 0.04])
    np.testing.assert_array_equal(mended.position[:, 0], [0.0, 2.0, 1.0, 4.0, 5.0])  # the later of the repeated time
    np.testing.assert_array_equal(mended.t_arrival, mended.t + 0.5)
