"""A live run's health from the files it logged, on runs written with known faults: a steady run is
valid, a rig or tracker that stalls makes it invalid with the stall named (how long, when), hitches
and dropped camera frames degrade it; and the video against the log: a camera that dropped its
frames exactly when the rig was slow gives a video that misses the whole run's latency, a warning
with both numbers."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Callable

import numpy as np
import pytest

from analysis import AnalysisError, AnalysisOptions
from predictors import SAMPLE_COLUMNS, PoseSample, sample_row
from rig.devices.window import SWAP_COLUMNS
from rig.live import health as thresholds
from rig.live import measure as live_measure
from rig.live.health import DEGRADED, INVALID, VALID, run_health
from rig.live.log_latency import log_latency
from rig.live.video_vs_log import video_against_log
from rig.lsl import PUBLISHED_COLUMNS
from rig.session.run_record import FRAME_COLUMNS
from rig.writers import CsvRecord

REFRESH_HZ = 60.0
RUN_S = 8.0
TRACKER_HZ = 500.0
CAMERA_FPS = 97.0
PERIOD_S = 1.2
AMPLITUDE_M = 0.1
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def _swing(t: np.ndarray) -> np.ndarray:
    return np.outer(AMPLITUDE_M * np.sin(2 * np.pi * t / PERIOD_S), [1.0, 0.0, 0.0])


def _write_run(folder: Path, swap_times: np.ndarray, delay_s: np.ndarray | float = 0.02, tracker_times: np.ndarray | None = None,
               camera_dropped: Callable[[np.ndarray], np.ndarray] | None = None,
               tracker_arrivals: np.ndarray | None = None) -> None:  # fmt: skip
    """A window run's files: a swap at each of `swap_times` showing the pose sampled `delay_s`
    before it, the tracker sampling at `tracker_times` (arriving 1 ms later, or at `tracker_arrivals`),
    the camera filming at CAMERA_FPS over the run with the frames `camera_dropped(t)` says filled in
    as dropped."""
    tracker_times = np.arange(0.0, RUN_S, 1.0 / TRACKER_HZ) if tracker_times is None else tracker_times
    arrivals = tracker_times + 0.001 if tracker_arrivals is None else tracker_arrivals
    with CsvRecord(folder / "tracker.csv", SAMPLE_COLUMNS) as record:
        for t, arrival, position in zip(tracker_times, arrivals, _swing(tracker_times)):
            record.write(sample_row(PoseSample(t, arrival, position, IDENTITY)))
    sensor = swap_times - delay_s
    with CsvRecord(folder / "display_swaps.csv", SWAP_COLUMNS) as swaps, CsvRecord(folder / "published_poses.csv",
                                                                                     PUBLISHED_COLUMNS) as poses:  # fmt: skip
        for i, (t, t_sensor, position) in enumerate(zip(swap_times, sensor, _swing(sensor))):
            swaps.write([i, i, i, 0, t, t, t, t, None, None])
            poses.write([i, t, t, t_sensor, *position, *IDENTITY])
    frames = np.arange(0.1, RUN_S - 0.1, 1.0 / CAMERA_FPS)
    dropped = np.zeros(len(frames), dtype=bool) if camera_dropped is None else camera_dropped(frames)
    with CsvRecord(folder / "camera_frames.csv", FRAME_COLUMNS) as record:
        for i, (t, filled) in enumerate(zip(frames, dropped)):
            record.write([i, t, None, int(filled)])


def _health(folder: Path) -> dict:
    return run_health(folder, REFRESH_HZ, 0.0, RUN_S, {"stalls": 0})


def _every_refresh(start: float = 0.01, end: float = RUN_S) -> np.ndarray:
    return np.arange(start, end, 1.0 / REFRESH_HZ)


def test_a_steady_run_is_valid_with_every_refresh_presented(tmp_path: Path) -> None:
    _write_run(tmp_path, _every_refresh())
    health = _health(tmp_path)
    assert health["verdict"] == VALID
    display = health["display"]
    assert display["refreshes_expected"] == 480 and display["refreshes_presented"] == 480
    assert display["longest_gap_ms"] == pytest.approx(1e3 / REFRESH_HZ, abs=0.1)
    assert health["pose_age"]["median_ms"] == pytest.approx(20.0, abs=1e-6)
    assert health["tracker"]["interval_ms"] == pytest.approx(2.0, abs=1e-6) and health["tracker"]["dropouts"] == 0
    assert health["camera"]["dropped"] == 0


def test_a_rig_that_stalls_mid_run_is_invalid_naming_the_stall(tmp_path: Path) -> None:
    swaps = _every_refresh()
    _write_run(tmp_path, swaps[(swaps < 3.0) | (swaps > 4.2)])
    health = _health(tmp_path)
    assert health["status"] == INVALID
    assert health["reasons"] == ["the rig stalled: no new image for 1217 ms from 3.0 s into the run"]
    assert health["display"]["refreshes_presented"] < health["display"]["refreshes_expected"] - 70


def test_a_rig_that_draws_two_images_then_stalls_to_the_end_is_invalid(tmp_path: Path) -> None:
    """A run that presented twice in eight seconds and ended 'completed' must not read as healthy."""
    _write_run(tmp_path, np.array([0.01, 0.03]))
    health = _health(tmp_path)
    assert health["status"] == INVALID
    assert health["reasons"] == ["the rig stalled: no new image for 7970 ms from 0.0 s into the run"]


def test_a_first_image_after_the_warm_up_is_a_stall_and_one_within_it_is_not(tmp_path: Path) -> None:
    (late := tmp_path / "late").mkdir()
    _write_run(late, _every_refresh(start=1.5))
    assert _health(late)["reasons"] == ["the rig stalled: its first image came 1500 ms after the run began"]
    (warming := tmp_path / "warming").mkdir()
    _write_run(warming, _every_refresh(start=0.6))
    assert _health(warming)["verdict"] == VALID


def test_a_tracker_silent_for_half_a_second_is_invalid(tmp_path: Path) -> None:
    t = np.arange(0.0, RUN_S, 1.0 / TRACKER_HZ)
    _write_run(tmp_path, _every_refresh(), tracker_times=t[(t < 5.0) | (t > 5.5)])
    health = _health(tmp_path)
    assert health["status"] == INVALID
    assert health["reasons"] == ["the tracker stalled: no sample arrived for 504 ms from 5.0 s into the run"]
    assert health["tracker"]["dropouts"] == 1 and health["tracker"]["longest_sensor_gap_ms"] == pytest.approx(504.0)


def test_a_tracker_whose_samples_arrive_late_in_a_burst_is_a_stall_though_none_is_missing(tmp_path: Path) -> None:
    """Samples measured on time but held back 400 ms and delivered together: the rig extrapolated."""
    t = np.arange(0.0, RUN_S, 1.0 / TRACKER_HZ)
    arrival = np.where((t > 5.0) & (t < 5.4), 5.4, t) + 0.001
    _write_run(tmp_path, _every_refresh(), tracker_times=t, tracker_arrivals=arrival)
    health = _health(tmp_path)
    assert health["tracker"]["dropouts"] == 0
    assert health["reasons"] == ["the tracker stalled: no sample arrived for 400 ms from 5.0 s into the run"]


def test_hitches_and_a_camera_that_drops_frames_degrade_the_run(tmp_path: Path) -> None:
    swaps = _every_refresh()
    _write_run(tmp_path, swaps[(swaps < 2.0) | (swaps > 2.15)], camera_dropped=lambda t: (t > 6.0) & (t < 6.2))
    health = _health(tmp_path)
    assert health["status"] == DEGRADED
    assert health["reasons"][0] == "the rig hitched: no new image for 167 ms from 2.0 s into the run"
    assert health["reasons"][1].startswith("the camera dropped 19 frames (2.5%), 19 in a row at 6.0 s")
    assert health["camera"]["drops"] == [{"at_s": pytest.approx(6.01, abs=0.01), "frames": 19}]


def test_a_display_repeating_most_images_degrades_the_run(tmp_path: Path) -> None:
    _write_run(tmp_path, np.arange(0.01, RUN_S, 3.0 / REFRESH_HZ))
    health = _health(tmp_path)
    assert health["status"] == DEGRADED
    assert health["reasons"] == ["the display showed a new image at 33% of refreshes (160 of 480)"]


def _slow_run(folder: Path, drops_when_slow: bool) -> tuple[dict, dict]:
    """A run whose rig is slow from 3 to 5 s (a new image every 80 ms, drawn from a pose 60 ms old,
    20 ms old otherwise), with a camera that dropped every frame then, or none; the video's answer
    as a camera that filmed what it kept would give it (the log's over those instants, +-3 ms)."""
    swaps = np.concatenate([_every_refresh(0.01, 3.0), np.arange(3.0, 5.0, 0.08), _every_refresh(5.0)])
    delay = np.where((swaps >= 3.0) & (swaps < 5.0), 0.06, 0.02)
    _write_run(folder, swaps, delay, camera_dropped=(lambda t: (t >= 3.0) & (t < 5.0)) if drops_when_slow else None)
    shown = {"t": swaps, "t_sensor": swaps - delay, **dict(zip(("px", "py", "pz"), _swing(swaps - delay).T))}
    frames = np.arange(0.1, RUN_S - 0.1, 1.0 / CAMERA_FPS)
    kept = frames[(frames < 3.0) | (frames >= 5.0)] if drops_when_slow else frames
    filmed = log_latency(folder, shown, instants=kept).latency_ms
    log = {"latency_ms": filmed, "whole_run_latency_ms": log_latency(folder, shown).latency_ms}
    return {"latency_ms": filmed, "ci95_ms": [filmed - 3.0, filmed + 3.0]}, log


def test_a_camera_that_drops_frames_when_the_rig_is_slow_gives_a_warning_with_both_numbers(tmp_path: Path) -> None:
    video, log = _slow_run(tmp_path, drops_when_slow=True)
    assert log["whole_run_latency_ms"] > video["ci95_ms"][1] + 3.0
    compared = video_against_log(tmp_path, video, log)
    assert compared["whole_run_in_interval"] is False
    assert compared["camera_drops"] == compared["drops_while_rig_slow"] == 194
    cause = compared["warning"]["cause"]
    assert f"{video['latency_ms']:.1f} ms" in cause and f"{log['whole_run_latency_ms']:.1f} ms" in cause
    assert "dropped 194 frames, 194 of them while the rig was slow" in cause
    assert "close other programs" in compared["warning"]["remedy"]


def test_a_camera_that_kept_every_frame_agrees_with_the_whole_run(tmp_path: Path) -> None:
    video, log = _slow_run(tmp_path, drops_when_slow=False)
    compared = video_against_log(tmp_path, video, log)
    assert compared["whole_run_in_interval"] is True and compared["warning"] is None
    assert compared["log_filmed_ms"] == pytest.approx(compared["log_whole_run_ms"], abs=1.0)


def test_the_documented_thresholds_are_the_declared_ones() -> None:
    page = (Path(__file__).resolve().parents[3] / "docs" / "run-health.md").read_text(encoding="utf-8")
    documented = dict(re.findall(r"^\| `([A-Z_]+)` \| ([0-9.]+)", page, flags=re.MULTILINE))
    assert documented.keys() == {"STALL_S", "WARM_UP_S", "HITCH_S", "MIN_PRESENTED_SHARE", "MAX_LATE_SHARE",
                                  "MAX_CAMERA_DROP_SHARE"}
    assert all(float(value) == getattr(thresholds, name) for name, value in documented.items())


@pytest.mark.parametrize(("status", "blames_the_run"), [("degraded", True), ("valid", False)])
def test_a_film_that_cannot_be_analysed_names_a_degraded_run_before_the_bench(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, status: str, blames_the_run: bool,
) -> None:
    def no_blob(*_: object) -> None:
        raise AnalysisError("no moving blob stands out in the sphere ROI; check that the pendulum swings")

    monkeypatch.setattr(live_measure, "analyse", no_blob)
    verdict = "degraded: the rig hitched: no new image for 150 ms from 2.0 s into the run" if blames_the_run else "valid"
    run = {"health": {"status": status, "reasons": [], "verdict": verdict}, "renderer": "warp"}
    with pytest.raises(AnalysisError) as raised:
        live_measure.analyse_run(tmp_path, 240.0, AnalysisOptions(), None, run)
    message = str(raised.value)
    assert message.startswith("no moving blob stands out")
    assert ("the run itself was degraded: the rig hitched: no new image for 150 ms" in message) is blames_the_run
