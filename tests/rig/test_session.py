"""A simulated run: timing of application and display frames, what it writes, and when."""

import csv
import json
import shutil
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pytest

from analysis.board.blink_code import align_blink_code
from analysis.board.recording import load_table
from rig.errors import ConfigError, RigError
from predictors import read_samples
from rig.service import SimulationConfig, simulate
from rig.sim.board import SimulatedBoardConfig, encoder_count
from rig.sim.camera import CameraConfig
from rig.sim.display import DisplayConfig
from rig.sim.pendulum import PendulumConfig
from rig.sim.tracker import TrackerConfig
from rig.sim.world import SimulatedWorld

SMALL_CAMERA = CameraConfig(fps=120.0, width=320, height=240, subsamples=4)


def small_config(**overrides) -> SimulationConfig:
    # Without prediction (hold), so that the true latency is the frame delay plus half a refresh.
    settings = dict(duration_s=1.5, camera=SMALL_CAMERA, display=DisplayConfig(width=160, height=120), predictor="hold")
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
    assert run.truth.display_frame_delay_ms.mean > 50.0


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
    assert truth.latency_ms == pytest.approx(truth.display_frame_delay_ms.mean + half_refresh_ms, abs=1.5)


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
    samples = read_samples(tmp_path / "tracker.csv")
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


# A lab's run: the board blinks its code while the pendulum is held, then the pendulum is let go.
BOARD = SimulatedBoardConfig(board_offset_s=100.0, blink_start_s=0.3, blink_bits=32, blink_bit_s=0.04)
RELEASE_S = 1.8


def lab_config(**overrides) -> SimulationConfig:
    return small_config(duration_s=3.0, pendulum=PendulumConfig(release_s=RELEASE_S), board=BOARD, **overrides)


@dataclass(frozen=True)
class LabRun:
    """A lab run's folder, and what its simulated world knows."""

    out_dir: Path
    config: SimulationConfig
    world: SimulatedWorld
    frame_times: np.ndarray


@pytest.fixture(scope="module")
def lab_run(tmp_path_factory: pytest.TempPathFactory) -> LabRun:
    config = lab_config()
    run = simulate(config, tmp_path_factory.mktemp("lab"))
    world = SimulatedWorld(config)
    return LabRun(run.out_dir, config, world, world.camera().frame_times)


def video_frames(video: Path) -> np.ndarray:
    """Every frame of the video, grey (N, height, width)."""
    capture = cv2.VideoCapture(str(video))
    frames = []
    while True:
        ok, frame = capture.read()
        if not ok:
            return np.array(frames)
        frames.append(frame[:, :, 1])


def exposure_levels(run: LabRun) -> np.ndarray:
    """The LED's level at 9 instants spread over each frame's exposure, shape (9, frames)."""
    exposure = run.config.camera.exposure
    return np.stack([BOARD.led_level(run.frame_times + f * exposure) for f in np.linspace(0.0, 1.0, 9)])


def test_a_run_without_a_board_records_none(default_run) -> None:
    assert not (default_run.out_dir / "board").exists()
    assert default_run.truth.board is None
    assert default_run.truth.config.pendulum.release_s is None


def test_truth_describes_the_board_and_the_release(lab_run) -> None:
    truth = json.loads((lab_run.out_dir / "truth.json").read_text())
    assert truth["board"] == {
        "offset_s": 100.0,
        "release_s": RELEASE_S,
        "blink": {"start_board_time": 100.3, "bit_s": 0.04, "seed": 0xACE1, "bits": 32, "level": 255},
    }
    assert truth["config"]["board"]["counts_per_rev"] == 2400


def test_the_board_record_aligns_the_cameras_truth_to_the_board_clock(lab_run) -> None:
    """Which frames have the LED on (the simulation knows) against led.csv gives the board's offset."""
    exposure = lab_run.config.camera.exposure
    middles = lab_run.frame_times + exposure / 2
    lit = BOARD.led_level(middles) > 0
    led = load_table(lab_run.out_dir / "board", "led.csv")
    alignment = align_blink_code(middles, lit, led["board_time_s"], led["level"], exposure_s=exposure)
    assert alignment.low_s - 1e-6 <= BOARD.board_offset_s <= alignment.high_s + 1e-6
    assert alignment.offset_s == pytest.approx(BOARD.board_offset_s, abs=1 / lab_run.config.camera.fps)
    assert alignment.agreement == 1.0


def test_the_video_shows_the_blink(lab_run) -> None:
    """The LED's brightest pixel is saturated in frames exposed wholly inside an on bit and dark in
    frames exposed wholly inside an off bit; the video's own on/off times the board's clock."""
    camera = lab_run.config.camera
    x, y, w, h = lab_run.world.layout.led_roi
    peaks = video_frames(lab_run.out_dir / "video.avi")[:, y : y + h, x : x + w].max(axis=(1, 2))
    assert peaks.size == lab_run.frame_times.size
    levels = exposure_levels(lab_run)
    on, off = np.all(levels > 0, axis=0), np.all(levels == 0, axis=0)
    assert off.sum() > 30 and on.sum() > 150
    assert peaks[on].min() >= 240
    assert peaks[off].max() <= camera.dark_dn + 6 * camera.noise_dn
    led = load_table(lab_run.out_dir / "board", "led.csv")
    middles = lab_run.frame_times + camera.exposure / 2
    alignment = align_blink_code(middles, peaks > 128, led["board_time_s"], led["level"], exposure_s=camera.exposure)
    assert alignment.low_s - 1e-6 <= BOARD.board_offset_s <= alignment.high_s + 1e-6


def test_encoder_csv_follows_the_pendulum_from_its_release(lab_run) -> None:
    encoder = load_table(lab_run.out_dir / "board", "encoder.csv")
    t, count, step = encoder["rig_time_s"], encoder["count"], encoder["step"]
    assert t.min() > RELEASE_S and t.max() <= lab_run.config.duration_s
    dense = encoder_count(lab_run.world.pendulum.angle(np.arange(lab_run.world.t_begin, lab_run.world.t_end, 20e-6)), BOARD.counts_per_rev)
    assert t.size == np.abs(np.diff(dense)).sum() > 500
    np.testing.assert_array_equal(encoder_count(lab_run.world.pendulum.angle(t - 1e-6), BOARD.counts_per_rev), count - step)
    np.testing.assert_array_equal(encoder_count(lab_run.world.pendulum.angle(t + 1e-6), BOARD.counts_per_rev), count)
    np.testing.assert_allclose(encoder["board_time_s"] - t, BOARD.board_offset_s, rtol=0, atol=1e-6)


def test_the_held_led_stays_put_in_the_video_until_the_release(lab_run) -> None:
    camera = lab_run.config.camera
    left = video_frames(lab_run.out_dir / "video.avi")[:, :, : camera.width // 2]
    bright = left.max(axis=1) > 128
    columns = (bright * (np.arange(left.shape[2]) + 0.5)).sum(axis=1) / np.maximum(bright.sum(axis=1), 1)
    lit = np.all(exposure_levels(lab_run) > 0, axis=0)
    held = lit & (lab_run.frame_times + camera.exposure < RELEASE_S)
    swinging = lab_run.frame_times > RELEASE_S + 0.1
    expected = lab_run.world.layout.led_pixels(lab_run.world.pendulum.led_position(np.array([0.0])))[0, 0]
    assert held.sum() > 60
    assert np.all(np.abs(columns[held] - expected) <= 1.0)
    assert np.ptp(columns[swinging]) > camera.width / 4


def test_a_held_run_keeps_its_true_latency(lab_run) -> None:
    truth = json.loads((lab_run.out_dir / "truth.json").read_text())
    half_refresh_ms = 1e3 / 60 / 2
    assert truth["latency_ms"] == pytest.approx(truth["display_frame_delay_ms"]["mean"] + half_refresh_ms, abs=1.5)


def test_an_interrupted_run_leaves_a_readable_board_recording(tmp_path: Path) -> None:
    def interrupt_after_two_seconds_of_film(done: float, total: float) -> None:
        if done > 2.0 + lab_config().warmup_s:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        simulate(lab_config(), tmp_path, progress=interrupt_after_two_seconds_of_film)
    led = load_table(tmp_path / "board", "led.csv")
    assert led["rig_time_s"].size > 10 and led["rig_time_s"].max() <= 2.1
    encoder = load_table(tmp_path / "board", "encoder.csv")
    assert encoder["rig_time_s"].size > 50
    assert RELEASE_S < encoder["rig_time_s"].min() and encoder["rig_time_s"].max() <= 2.1
    assert not (tmp_path / "board" / "recording.json").exists()


def test_overwriting_a_board_run_removes_its_recording(lab_run, tmp_path: Path) -> None:
    folder = tmp_path / "run"
    shutil.copytree(lab_run.out_dir, folder)
    with pytest.raises(RigError, match="board"):
        simulate(small_config(), folder)
    simulate(small_config(), folder, overwrite=True)
    assert not (folder / "board").exists()


@pytest.mark.parametrize(
    "overrides, message",
    [
        (dict(pendulum=PendulumConfig(release_s=2.5)), "release at 2.5 s must fall within the filmed span"),
        (dict(pendulum=PendulumConfig(release_s=-0.1)), "release at -0.1 s must fall within the filmed span"),
        (dict(board=SimulatedBoardConfig(blink_start_s=2.0, blink_bits=32, blink_bit_s=0.04)), r"blink \(2 s to 3.28 s\) must fall within the filmed span"),
        (dict(board=SimulatedBoardConfig(blink_start_s=0.0)), "blink .* must fall within the filmed span"),
    ],
)
def test_a_release_or_blink_outside_the_film_is_rejected(overrides: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        SimulationConfig(**{"duration_s": 3.0, **overrides})
