"""The rig's own answer from its logs, on logs written for a known delay; and the view that frames
a swing whatever the tracker's axes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from predictors import SAMPLE_COLUMNS, PoseSample, sample_row
from rig.errors import RigError
from rig.live.log_latency import log_latency
from rig.live.view import view_from_positions
from rig.writers import CsvRecord

PERIOD_S = 1.2
REFRESH_S = 1.0 / 60.0
AMPLITUDE_M = 0.1


def _swing(t: np.ndarray, axis: np.ndarray) -> np.ndarray:
    return np.outer(AMPLITUDE_M * np.sin(2 * np.pi * t / PERIOD_S), axis) + np.array([0.3, -0.2, 1.0])


def _write_tracker(folder: Path, axis: np.ndarray, rate_hz: float = 500.0, seconds: float = 8.0) -> None:
    t = np.arange(0.0, seconds, 1.0 / rate_hz)
    with CsvRecord(folder / "tracker.csv", SAMPLE_COLUMNS) as record:
        for ti, position in zip(t, _swing(t, axis)):
            record.write(sample_row(PoseSample(ti, ti + 0.002, position, np.array([1.0, 0.0, 0.0, 0.0]))))


@pytest.mark.parametrize("delay_ms", [0.0, 23.0, 61.5])
def test_held_frames_shown_a_fixed_delay_after_their_sample_give_that_delay_plus_half_a_hold(tmp_path: Path, delay_ms: float) -> None:
    axis = np.array([0.6, 0.0, 0.8])
    _write_tracker(tmp_path, axis)
    switch = np.arange(0.2, 7.8, REFRESH_S)
    sensor = switch - delay_ms / 1e3
    positions = _swing(sensor, axis)
    shown = {"t": switch, "t_sensor": sensor, "px": positions[:, 0], "py": positions[:, 1], "pz": positions[:, 2]}
    result = log_latency(tmp_path, shown)
    # a frame held for a refresh lags its sample by the delay plus half the hold, on average
    assert result.latency_ms == pytest.approx(delay_ms + 0.5 * REFRESH_S * 1e3, abs=0.2)
    assert result.delay_mean_ms == pytest.approx(delay_ms, abs=1e-6)
    assert result.period_s == pytest.approx(PERIOD_S, rel=1e-3)


def test_a_scan_out_delay_adds_to_the_logged_latency(tmp_path: Path) -> None:
    axis = np.array([1.0, 0.0, 0.0])
    _write_tracker(tmp_path, axis)
    switch = np.arange(0.2, 7.8, REFRESH_S)
    positions = _swing(switch, axis)
    shown = {"t": switch, "t_sensor": switch, "px": positions[:, 0], "py": positions[:, 1], "pz": positions[:, 2]}
    plain = log_latency(tmp_path, shown).latency_ms
    assert log_latency(tmp_path, shown, 0.004).latency_ms == pytest.approx(plain + 4.0, abs=0.1)


def test_at_the_instants_a_camera_filmed_the_log_weights_the_run_as_the_video_does(tmp_path: Path) -> None:
    axis = np.array([1.0, 0.0, 0.0])
    _write_tracker(tmp_path, axis)
    switch = np.arange(0.2, 7.8, REFRESH_S)
    # 20 ms behind until 4 s, then 60 ms: a camera that filmed only the first half sees 20 ms
    sensor = switch - np.where(switch < 4.0, 0.020, 0.060)
    positions = _swing(sensor, axis)
    shown = {"t": switch, "t_sensor": sensor, "px": positions[:, 0], "py": positions[:, 1], "pz": positions[:, 2]}
    instants = np.random.default_rng(2).uniform(0.8, 3.9, 400)
    first_half = log_latency(tmp_path, shown, instants=np.sort(instants)).latency_ms
    assert first_half == pytest.approx(20.0 + 0.5 * REFRESH_S * 1e3, abs=0.5)
    assert log_latency(tmp_path, shown).latency_ms > first_half + 10.0


def test_too_short_a_log_is_refused(tmp_path: Path) -> None:
    _write_tracker(tmp_path, np.array([1.0, 0.0, 0.0]), seconds=2.0)
    switch = np.arange(0.2, 1.8, REFRESH_S)
    positions = _swing(switch, np.array([1.0, 0.0, 0.0]))
    shown = {"t": switch, "t_sensor": switch, "px": positions[:, 0], "py": positions[:, 1], "pz": positions[:, 2]}
    with pytest.raises(RigError, match="too short|fewer than three swings"):
        log_latency(tmp_path, shown)


def test_the_view_frames_a_swing_along_any_axis_across_the_screen() -> None:
    axis = np.array([0.0, 0.6, -0.8])
    t = np.linspace(0.0, PERIOD_S, 200)
    positions = _swing(t, axis) + np.outer(0.01 * np.cos(4 * np.pi * t / PERIOD_S), [1.0, 0.0, 0.0])
    view = view_from_positions(positions, 320, 240)
    clip = np.column_stack([positions, np.ones(len(t))]) @ view.world_to_clip.T
    assert np.max(np.abs(clip[:, 0])) == pytest.approx(0.7, abs=0.01)
    assert np.max(np.abs(clip[:, 1])) < 0.3
    # the sphere moves the way the swing's larger component goes (here world z)
    assert np.corrcoef(clip[:, 0], positions[:, 2])[0, 1] > 0.99
    mirrored = view_from_positions(positions, 320, 240, mirror=True)
    assert np.allclose(mirrored.world_to_clip[0], -view.world_to_clip[0])


def test_a_tracker_that_hardly_moves_cannot_frame_a_view() -> None:
    still = np.array([0.3, -0.2, 1.0]) + np.random.default_rng(0).normal(0.0, 1e-4, (50, 3))
    with pytest.raises(RigError, match="release the pendulum"):
        view_from_positions(still, 320, 240)
