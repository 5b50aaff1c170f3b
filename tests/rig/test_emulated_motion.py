"""The emulated tracker measures what the simulated tracker measures: a pose for every sample it is
asked to send, on the pendulum or a trace in a loop, with the angular rate that turns each sample's
orientation into the next one's, and the transport the tracker's configuration gives."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from predictors import PoseSample, quaternion, sample_row
from predictors.trace import SAMPLE_COLUMNS
from rig.emulate import EmulatorConfig, emulated_motion, emulated_samples, quiet_tracker
from rig.writers import CsvRecord
from rig.sim.tracker import TrackerConfig


def test_a_short_slow_stream_has_a_pose_for_its_last_sample() -> None:
    samples, rates = emulated_samples(EmulatorConfig("pty", "unused", quiet_tracker(200.0), 1.0))
    assert samples.seq.tolist() == list(range(200)) and not samples.lost.any()
    assert np.all(np.isfinite(samples.positions)) and np.all(np.isfinite(rates))


@settings(max_examples=15, deadline=None)
@given(rate_hz=st.floats(30.0, 2000.0), duration_s=st.floats(0.05, 6.0))
def test_every_sample_of_a_stream_has_a_unit_orientation_sent_when_it_was_measured(rate_hz: float, duration_s: float) -> None:
    samples, _ = emulated_samples(EmulatorConfig("pty", "unused", quiet_tracker(rate_hz), duration_s))
    assert samples.t_sensor[-1] < duration_s <= samples.t_sensor[-1] + 1.0 / rate_hz + 1e-12, "the stream's last sample is there"
    np.testing.assert_allclose(np.linalg.norm(samples.orientations, axis=1), 1.0, atol=1e-9)
    np.testing.assert_array_equal(samples.t_arrival, samples.t_sensor)


def test_the_angular_rate_turns_each_orientation_into_the_next_samples() -> None:
    rate_hz = 500.0
    samples, rates = emulated_samples(EmulatorConfig("pty", "unused", quiet_tracker(rate_hz), 2.0))
    q = samples.orientations
    turns = quaternion.to_rotation_vector(quaternion.multiply(quaternion.conjugate(q[:-1]), q[1:])) * rate_hz
    np.testing.assert_allclose(rates[:-1], turns, atol=1e-9)
    assert np.abs(rates).max() > 1.0, "the pendulum swings: its rate is rad/s, not zero"


def test_the_transport_delays_and_loses_as_the_tracker_is_configured() -> None:
    tracker = TrackerConfig(rate_hz=1000.0, transport_delay_s=0.004, jitter_s=0.001, dropout=0.2)
    samples, _ = emulated_samples(EmulatorConfig("tcp", "0", tracker, 3.0, seed=5))
    kept = ~samples.lost
    lateness = samples.t_arrival[kept] - samples.t_sensor[kept]
    assert np.all(lateness >= 0.004 - 1e-12) and np.all(np.diff(samples.t_arrival[kept]) >= 0.0)
    assert samples.lost.mean() == pytest.approx(0.2, abs=5 * math.sqrt(0.2 * 0.8 / 3000))


def test_a_trace_is_played_in_a_loop(tmp_path: Path) -> None:
    path = tmp_path / "trace.csv"
    with CsvRecord(path, SAMPLE_COLUMNS) as trace:
        for k in range(11):
            angle = 0.1 * k
            trace.write(sample_row(PoseSample(0.1 * k, 0.1 * k + 0.01, np.array([k, 0.0, 0.0]), np.array([math.cos(angle), 0, 0, math.sin(angle)]))))
    motion = emulated_motion(EmulatorConfig("pty", "unused", quiet_tracker(100.0), 5.0, trace=path))
    positions, _ = motion.sensor_pose(np.array([0.25, 1.25, 2.25]))
    np.testing.assert_allclose(positions[:, 0], [2.5, 2.5, 2.5], atol=1e-9)
