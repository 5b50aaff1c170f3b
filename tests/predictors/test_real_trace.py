"""The issue's acceptance case on the recorded head motion (`data/traces/hmd_orientation_user1.csv`):
tuned on its first 60%, the damped `kalman-cv` and the tuned `auto` predict the last 40% better
than slerp extrapolation at 20, 50 and 100 ms.

The parameters are what `rig tune kalman-cv|auto --trace data/traces/hmd_orientation_user1.csv
--horizon-ms H` fits on the first 60% (rounded to three digits); the held-out part never saw them
fitted. Tuning them here would take a minute of JAX: this replays the real-time predictors only.
"""

from pathlib import Path

import pytest

from predictors import make, read_trace
from predictors.evaluation import replay, score

TRACE = Path(__file__).resolve().parents[2] / "data" / "traces" / "hmd_orientation_user1.csv"

KALMAN_CV = {
    20.0: {"angular_acceleration_noise": 4.69, "angular_velocity_damping": 4.43},
    50.0: {"angular_acceleration_noise": 3.82, "angular_velocity_damping": 3.82},
    100.0: {"angular_acceleration_noise": 2.77, "angular_velocity_damping": 3.17},
}
AUTO = {
    20.0: {**KALMAN_CV[20.0], "memory": 0.5, "margin": 0.05},
    50.0: {**KALMAN_CV[50.0], "memory": 0.1, "margin": 0.4},
    100.0: {**KALMAN_CV[100.0], "memory": 0.2, "margin": 0.4},
}


@pytest.fixture(scope="module")
def held_out():
    return read_trace(TRACE).split(0.6)[1]


def angular_rms_deg(trace, name: str, params: dict, horizon_ms: float) -> float:
    """`evaluate`'s angular RMS error, without its timing replays."""
    horizons = [horizon_ms / 1e3]
    return score(trace, horizons, *replay(make(name, **params), trace, horizons))[0].angular_rms_deg


@pytest.mark.parametrize("horizon_ms", [20.0, 50.0, 100.0])
def test_tuned_kalman_cv_and_auto_beat_slerp_on_the_held_out_real_trace(held_out, horizon_ms):
    slerp = angular_rms_deg(held_out, "slerp", {}, horizon_ms)
    assert angular_rms_deg(held_out, "kalman-cv", KALMAN_CV[horizon_ms], horizon_ms) < slerp
    assert angular_rms_deg(held_out, "auto", AUTO[horizon_ms], horizon_ms) < slerp


def test_without_damping_the_tuned_kalman_cv_does_not_beat_slerp_at_20_ms(held_out):
    """Why the damping: the noise ratio alone (fitted the same way, without it) loses at 20 ms."""
    undamped = angular_rms_deg(held_out, "kalman-cv", {"angular_acceleration_noise": 4.26}, 20.0)
    assert undamped > angular_rms_deg(held_out, "slerp", {}, 20.0)
