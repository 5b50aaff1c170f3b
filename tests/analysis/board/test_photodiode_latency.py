"""Latency from photodiode passages against the encoder, on recordings with a known latency."""

from __future__ import annotations

import numpy as np
import pytest

from analysis.board.photodiode_latency import estimate_board_latency
from analysis.errors import AnalysisError


def estimate(recording, **options):
    return estimate_board_latency(
        recording.edge_times, recording.counts, recording.steps, recording.centroids, recording.durations, **options
    )


@pytest.mark.parametrize("latency", [0.0, 0.0125, 0.1, 0.5])
def test_known_latency_is_recovered(synthetic_recording, latency: float) -> None:
    recording = synthetic_recording(latency)
    result = estimate(recording)
    assert result.latency_s == pytest.approx(latency, abs=20e-6)
    assert abs(result.latency_s - latency) < 5 * result.uncertainty_s + 2e-6
    assert result.uncertainty_s < 10e-6
    # The photodiode at 0.02 rad is 7.64 counts from the bottom of the swing.
    assert result.photodiode_counts == pytest.approx(0.02 * 2400 / (2 * np.pi), abs=0.05)
    assert result.period_s == pytest.approx(1.25, rel=1e-3)


def test_photodiode_far_up_the_swing(synthetic_recording) -> None:
    result = estimate(synthetic_recording(0.03, photodiode=0.2, seed=1))
    assert result.latency_s == pytest.approx(0.03, abs=50e-6)


def test_damped_swing(synthetic_recording) -> None:
    result = estimate(synthetic_recording(0.02, decay=20.0, seed=2))
    assert result.latency_s == pytest.approx(0.02, abs=50e-6)


def test_encoder_reporting_at_a_set_rate(synthetic_recording) -> None:
    recording = synthetic_recording(0.02, seed=3)
    # At 200 reports per second the board sends only the latest edge of each 5 ms.
    slot = np.floor(recording.edge_times / 0.005)
    latest = np.append(slot[1:] != slot[:-1], True)
    sparse = estimate_board_latency(
        recording.edge_times[latest], recording.counts[latest], recording.steps[latest], recording.centroids, recording.durations
    )
    assert sparse.latency_s == pytest.approx(0.02, abs=0.2e-3)


def test_latency_near_the_largest_searched(synthetic_recording) -> None:
    recording = synthetic_recording(0.55)
    assert estimate(recording, max_latency_s=0.6).latency_s == pytest.approx(0.55, abs=20e-6)


def test_a_latency_of_half_a_period_or_more_cannot_be_searched(synthetic_recording) -> None:
    with pytest.raises(AnalysisError, match="half the pendulum period"):
        estimate(synthetic_recording(0.01), max_latency_s=0.7)


def test_passages_in_one_direction_only_are_refused(synthetic_recording) -> None:
    recording = synthetic_recording(0.01)
    # Every other passage: the sphere always passing the same way.
    with pytest.raises(AnalysisError, match="both directions"):
        estimate_board_latency(
            recording.edge_times, recording.counts, recording.steps, recording.centroids[::2], recording.durations[::2]
        )


def test_too_little_data_is_refused(synthetic_recording) -> None:
    recording = synthetic_recording(0.01)
    with pytest.raises(AnalysisError, match="fewer than 10 encoder edges"):
        estimate_board_latency(recording.edge_times[:5], recording.counts[:5], recording.steps[:5], recording.centroids, recording.durations)
    with pytest.raises(AnalysisError, match="at least 4 passages"):
        estimate_board_latency(recording.edge_times, recording.counts, recording.steps, recording.centroids[:3], recording.durations[:3])
    short = synthetic_recording(0.01, duration=1.0)
    with pytest.raises(AnalysisError, match="less than one pendulum period"):
        estimate(short)
