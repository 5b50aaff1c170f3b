"""A simulated run: timing of application and display frames, what it writes, and when."""

import csv
import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from rig.errors import RigError
from rig.session import SimulationConfig, simulate
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.tracker import TrackerConfig, read_tracker_csv

SMALL_CAMERA = CameraConfig(fps=120.0, width=320, height=240, subsamples=4)


def small_config(**overrides) -> SimulationConfig:
    settings = dict(duration_s=1.5, camera=SMALL_CAMERA, display=DisplayConfig(width=160, height=120))
    settings.update(overrides)
    return SimulationConfig(**settings)


def read_rows(path: Path) -> list[dict[str, str]]:
    with path.open() as stream:
        return list(csv.DictReader(stream))


@pytest.fixture(scope="module")
def default_run(tmp_path_factory: pytest.TempPathFactory):
    return simulate(small_config(), tmp_path_factory.mktemp("run"))


def test_a_run_writes_its_record(default_run) -> None:
    out = default_run.out_dir
    for name in ("video.avi", "truth.json", "tracker.csv", "app_frames.csv", "display_frames.csv"):
        assert (out / name).stat().st_size > 0
    truth = json.loads((out / "truth.json").read_text())
    assert truth["camera_fps"] == 120.0
    assert truth["frames"] == 179
    assert truth["config"]["predictor"] == "hold"
    capture = cv2.VideoCapture(str(default_run.video_path))
    assert int(capture.get(cv2.CAP_PROP_FRAME_COUNT)) == truth["frames"]


def test_same_seed_gives_the_same_run(default_run, tmp_path: Path) -> None:
    again = simulate(small_config(), tmp_path)
    assert again.truth == default_run.truth
    assert (tmp_path / "tracker.csv").read_bytes() == (default_run.out_dir / "tracker.csv").read_bytes()


def test_short_frames_are_shown_at_the_next_blank_one_per_refresh(default_run) -> None:
    """A 5 ms frame started at a blank is shown one refresh later and replaced every refresh."""
    rows = read_rows(default_run.out_dir / "display_frames.csv")
    images = [int(r["image"]) for r in rows]
    assert images == list(range(images[0], images[0] + len(images)))
    apps = read_rows(default_run.out_dir / "app_frames.csv")
    period = 1 / 60
    starts = np.array([float(a["t_start"]) for a in apps[1:]])
    np.testing.assert_allclose(np.diff(starts), period, rtol=1e-9)


def test_long_frames_are_repeated_until_the_next_is_ready(tmp_path: Path) -> None:
    """A 40 ms frame at 60 Hz finishes within the third refresh and is shown for three."""
    run = simulate(small_config(app_frame_ms=40.0), tmp_path)
    images = [int(r["image"]) for r in read_rows(tmp_path / "display_frames.csv")]
    repeats = np.diff(np.flatnonzero(np.diff(images)))
    assert set(repeats.tolist()) == {3}
    delay = run.truth["display_frame_delay_ms"]
    assert delay["mean"] > 50.0


def test_each_display_frame_delay_is_photon_time_minus_newest_sample(default_run) -> None:
    tracker = TrackerConfig()
    for row in read_rows(default_run.out_dir / "display_frames.csv"):
        delay = float(row["t_photon"]) - float(row["t_sensor_newest"])
        assert float(row["delay_ms"]) == pytest.approx(delay * 1e3)
        # at least the transport delay plus one refresh (rendered in one, shown in the next)
        assert delay > tracker.transport_delay_s + 1 / 60


def test_true_latency_lies_half_a_refresh_beyond_the_mean_frame_delay(default_run) -> None:
    truth = default_run.truth
    half_refresh_ms = 1e3 / 60 / 2
    assert truth["latency_ms"] == pytest.approx(truth["display_frame_delay_ms"]["mean"] + half_refresh_ms, abs=1.5)


def test_an_existing_run_is_not_overwritten(default_run) -> None:
    before = (default_run.out_dir / "truth.json").read_bytes()
    with pytest.raises(RigError, match="already holds a run"):
        simulate(small_config(seed=9), default_run.out_dir)
    assert (default_run.out_dir / "truth.json").read_bytes() == before


def test_an_interrupted_run_leaves_a_readable_partial_record(tmp_path: Path) -> None:
    def interrupt_halfway(done: float, total: float) -> None:
        if done > total / 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        simulate(small_config(), tmp_path, progress=interrupt_halfway)
    assert not (tmp_path / "truth.json").exists()
    samples = read_tracker_csv(tmp_path / "tracker.csv")
    assert len(samples) > 60
    assert len(read_rows(tmp_path / "display_frames.csv")) > 30
    capture = cv2.VideoCapture(str(tmp_path / "video.avi"))
    frames = 0
    while capture.read()[0]:
        frames += 1
    assert frames > 40


def test_unknown_renderer_and_predictor_are_reported(tmp_path: Path) -> None:
    from predictors import PredictorError

    with pytest.raises(RigError, match="direct"):
        simulate(small_config(renderer="nonesuch"), tmp_path / "a")
    with pytest.raises(PredictorError):
        simulate(small_config(predictor="nonesuch"), tmp_path / "b")
