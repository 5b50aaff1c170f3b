"""The simulated tracker against its configuration and its faults in time, and the tracker CSV format."""

import math

import numpy as np
import pytest

from predictors import PoseSample
from rig.clock import VirtualClock
from rig.errors import ConfigError, RigError
from rig.sim.pendulum import Pendulum, PendulumConfig
from rig.sim.tracker import SimTracker, TrackerConfig, measure
from rig.sim.fault_plan import parse_faults

QUIET = dict(position_noise_m=0.0, orientation_noise_deg=0.0, jitter_s=0.0)


@pytest.fixture(scope="module")
def pendulum() -> Pendulum:
    return Pendulum(PendulumConfig(amplitude_deg=30.0, pivot=(0.0, 1.0, 0.0)), 30.0)


def _columns(samples: list[PoseSample]) -> dict[str, np.ndarray]:
    return {
        "t_sensor": np.array([s.t_sensor for s in samples]),
        "t_arrival": np.array([s.t_arrival for s in samples]),
        "position": np.array([s.position for s in samples]).reshape(-1, 3),
        "orientation": np.array([s.orientation for s in samples]).reshape(-1, 4),
    }


def _body_frame_rotation_vector(truth: np.ndarray, measured: np.ndarray) -> np.ndarray:
    """Rotation vector of conj(truth) * measured, for truths that rotate about z only."""
    c, s = truth[:, 0], truth[:, 3]
    w, x, y, z = measured.T
    relative = np.stack([c * w + s * z, c * x + s * y, c * y - s * x, c * z - s * w], axis=1)
    relative *= np.sign(relative[:, :1])
    vector = relative[:, 1:]
    norm = np.linalg.norm(vector, axis=1, keepdims=True)
    return 2.0 * np.arctan2(norm, relative[:, :1]) * vector / norm


def test_same_seed_gives_the_same_samples_and_another_seed_does_not(pendulum):
    config = TrackerConfig(dropout=0.1)
    first = _columns(measure(pendulum, config, 0.0, 2.0, seed=7).pose_samples())
    again = _columns(measure(pendulum, config, 0.0, 2.0, seed=7).pose_samples())
    other = _columns(measure(pendulum, config, 0.0, 2.0, seed=8).pose_samples())
    for name in first:
        np.testing.assert_array_equal(first[name], again[name])
    assert not np.array_equal(first["position"], other["position"][: len(first["position"])])
    assert not np.array_equal(first["t_sensor"], other["t_sensor"])


def test_samples_come_at_the_configured_rate_and_phase(pendulum):
    config = TrackerConfig(rate_hz=100.0, phase_s=0.003, **QUIET)
    t_sensor = _columns(measure(pendulum, config, 1.0, 3.0, seed=0).pose_samples())["t_sensor"]
    assert t_sensor.size == 200
    np.testing.assert_allclose(t_sensor, 1.003 + np.arange(200) / 100.0, rtol=0, atol=1e-12)


def test_last_sample_is_before_the_window_end(pendulum):
    t_sensor = _columns(measure(pendulum, TrackerConfig(rate_hz=10.0), 0.0, 1.0, seed=0).pose_samples())["t_sensor"]
    assert t_sensor.size == 10
    assert t_sensor[-1] < 1.0


def test_noise_has_the_configured_spread(pendulum):
    config = TrackerConfig(position_noise_m=0.001, orientation_noise_deg=0.5, dropout=0.0)
    columns = _columns(measure(pendulum, config, 0.0, 25.0, seed=3).pose_samples())
    n = columns["t_sensor"].size
    assert n == 3000
    true_positions, true_orientations = pendulum.sensor_pose(columns["t_sensor"])
    rotation_error = _body_frame_rotation_vector(true_orientations, columns["orientation"])
    # The standard error of a sample std-dev is about 1 / sqrt(2 n) = 1.3 %: allow 5 of them.
    for error, sigma in [
        (columns["position"] - true_positions, 0.001),
        (rotation_error, math.radians(0.5)),
    ]:
        np.testing.assert_allclose(np.std(error, axis=0), sigma, rtol=0.065)
        np.testing.assert_allclose(np.mean(error, axis=0), 0.0, atol=5 * sigma / math.sqrt(n))
    np.testing.assert_allclose(np.linalg.norm(columns["orientation"], axis=1), 1.0, atol=1e-15)


def test_arrival_is_late_by_the_delay_plus_the_mean_jitter(pendulum):
    config = TrackerConfig(transport_delay_s=0.004, jitter_s=0.0005)
    columns = _columns(measure(pendulum, config, 0.0, 25.0, seed=4).pose_samples())
    lateness = columns["t_arrival"] - columns["t_sensor"]
    assert np.all(lateness >= 0.004 - 1e-12)
    n = lateness.size
    # Exponential jitter: its std-dev equals its mean.
    assert np.mean(lateness) == pytest.approx(0.0045, abs=5 * 0.0005 / math.sqrt(n))
    assert np.std(lateness) == pytest.approx(0.0005, rel=0.1)


def test_transport_never_reorders_samples(pendulum):
    config = TrackerConfig(rate_hz=120.0, transport_delay_s=0.002, jitter_s=0.02)
    columns = _columns(measure(pendulum, config, 0.0, 5.0, seed=5).pose_samples())
    steps = np.diff(columns["t_arrival"])
    assert np.all(steps >= 0.0)
    assert np.count_nonzero(steps == 0.0) > 10, "jitter this large must make samples queue behind late ones"
    assert np.all(np.diff(columns["t_sensor"]) > 0.0)
    assert np.all(columns["t_arrival"] - columns["t_sensor"] >= 0.002 - 1e-12)


def test_dropout_removes_the_configured_fraction_and_keeps_the_rest_unchanged(pendulum):
    full = _columns(measure(pendulum, TrackerConfig(jitter_s=0.0), 0.0, 25.0, seed=6).pose_samples())
    thinned_config = TrackerConfig(jitter_s=0.0, dropout=0.3)
    thinned = _columns(measure(pendulum, thinned_config, 0.0, 25.0, seed=6).pose_samples())
    n = full["t_sensor"].size
    kept = thinned["t_sensor"].size / n
    assert kept == pytest.approx(0.7, abs=5 * math.sqrt(0.3 * 0.7 / n))
    index = np.searchsorted(full["t_sensor"], thinned["t_sensor"])
    np.testing.assert_array_equal(full["t_sensor"][index], thinned["t_sensor"])
    np.testing.assert_array_equal(full["position"][index], thinned["position"])
    np.testing.assert_array_equal(full["orientation"][index], thinned["orientation"])


def test_zero_noise_gives_the_exact_truth(pendulum):
    config = TrackerConfig(transport_delay_s=0.004, **QUIET)
    columns = _columns(measure(pendulum, config, 0.0, 3.0, seed=1).pose_samples())
    positions, orientations = pendulum.sensor_pose(columns["t_sensor"])
    np.testing.assert_array_equal(columns["position"], positions)
    np.testing.assert_allclose(columns["orientation"], orientations, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(columns["t_arrival"], columns["t_sensor"] + 0.004)


def test_a_window_too_short_for_one_sample_gives_none(pendulum):
    assert measure(pendulum, TrackerConfig(phase_s=0.005), 0.0, 0.004, seed=0).pose_samples() == []


@pytest.mark.parametrize("t_start, t_end", [(-0.1, 1.0), (0.0, 30.5)])
def test_a_window_outside_the_pendulum_raises(pendulum, t_start, t_end):
    with pytest.raises(ConfigError, match="not inside the motion"):
        measure(pendulum, TrackerConfig(), t_start, t_end, seed=0).pose_samples()


def test_an_empty_window_raises(pendulum):
    with pytest.raises(ConfigError, match="t_end > t_start"):
        measure(pendulum, TrackerConfig(), 1.0, 1.0, seed=0).pose_samples()


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(rate_hz=0.0), "tracker.rate_hz must be a positive number of Hz from 1 to 5000, got 0.0"),
        (dict(rate_hz=math.inf), "tracker.rate_hz must be a positive number of Hz from 1 to 5000, got inf"),
        (dict(position_noise_m=-1e-3), "tracker.position_noise_m must be a number of metres from 0 to 0.1, got -0.001"),
        (dict(orientation_noise_deg=math.nan), "tracker.orientation_noise_deg must be a number of degrees from 0 to 10, got nan"),
        (dict(transport_delay_s=-0.001), "tracker.transport_delay_s must be a number of seconds from 0 to 1, got -0.001"),
        (dict(jitter_s=math.inf), "tracker.jitter_s must be a number of seconds from 0 to 0.1, got inf"),
        (dict(dropout=1.0), "tracker.dropout must be zero or a positive number below 1, got 1.0"),
        (dict(dropout=-0.1), "tracker.dropout must be zero or a positive number below 1, got -0.1"),
        (dict(rate_hz=100.0, phase_s=0.01), r"phase_s must be in \[0, 1 / rate_hz\)"),
        (dict(phase_s=-0.001), "tracker.phase_s must be zero or a positive number of seconds below 1, got -0.001"),
    ],
)
def test_config_rejects_bad_values(kwargs, message):
    with pytest.raises(ConfigError, match=message):
        TrackerConfig(**kwargs)


def test_the_simulated_tracker_hands_out_each_sample_once_its_arrival_has_passed(pendulum):
    tracker = SimTracker(pendulum, TrackerConfig(), 0.0, 1.0, seed=4)
    expected = measure(pendulum, TrackerConfig(), 0.0, 1.0, seed=4).pose_samples()
    clock = VirtualClock(-0.5)
    tracker.connect(clock)
    first = tracker.wait(timeout_s=1.0)
    assert clock.now() == expected[0].t_arrival
    got = list(first)
    for t in np.arange(0.0, 1.1, 0.013):
        clock.wait_until(float(t))
        arrived = tracker.poll()
        assert all(s.t_arrival <= clock.now() for s in arrived)
        got += arrived
    tracker.close()
    assert [s.t_sensor for s in got] == [s.t_sensor for s in expected]


def test_waiting_gives_nothing_when_no_sample_comes_in_time(pendulum):
    tracker = SimTracker(pendulum, TrackerConfig(transport_delay_s=0.5), 0.0, 1.0, seed=4)
    clock = VirtualClock(0.0)
    tracker.connect(clock)
    assert tracker.wait(timeout_s=0.1) == []
    assert clock.now() == 0.0


def test_an_unconnected_tracker_says_so(pendulum):
    with pytest.raises(RigError, match="not connected"):
        SimTracker(pendulum, TrackerConfig(), 0.0, 1.0, seed=4).poll()


def test_a_stall_holds_what_would_arrive_during_it_until_its_end(pendulum):
    quiet = TrackerConfig(rate_hz=100.0, **QUIET)
    samples = measure(pendulum, quiet, 0.0, 2.0, seed=0, faults=parse_faults("stall=0.5:0.25"))
    held = (samples.t_sensor >= 0.5) & (samples.t_sensor < 0.75)
    assert held.sum() == 25 and not samples.lost.any()
    np.testing.assert_array_equal(samples.t_arrival[held], 0.75)
    np.testing.assert_array_equal(samples.t_arrival[~held], samples.t_sensor[~held] + 0.004)


def test_a_burst_holds_each_group_until_its_last_record(pendulum):
    samples = measure(pendulum, TrackerConfig(rate_hz=100.0, dropout=0.1, **QUIET), 0.0, 1.0, seed=2, faults=parse_faults("burst=4"))
    sent = samples.t_arrival[~samples.lost]
    groups = [sent[k : k + 4] for k in range(0, sent.size, 4)]
    assert all(np.all(group == group[-1]) for group in groups)
    assert [group[-1] for group in groups] == sorted({*sent.tolist()}), "each group arrives at a time of its own"


def test_a_disconnect_loses_what_would_arrive_while_the_link_is_away(pendulum):
    tracker = SimTracker(pendulum, TrackerConfig(rate_hz=100.0, **QUIET), 0.0, 2.0, seed=0, faults=parse_faults("disconnect=1:0.5"))
    tracker.connect(VirtualClock(0.0))
    arrived = []
    while more := tracker.wait(timeout_s=3.0):
        arrived += more
    arrivals = np.array([s.t_arrival for s in arrived])
    assert arrivals.size == 200 - 50
    assert not np.any((arrivals >= 1.0) & (arrivals < 1.5))


def test_an_in_process_tracker_refuses_faults_in_bytes(pendulum):
    with pytest.raises(ConfigError, match="no bytes to damage"):
        SimTracker(pendulum, TrackerConfig(), 0.0, 1.0, seed=0, faults=parse_faults("corrupt=0.01"))
