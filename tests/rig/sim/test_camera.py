"""The simulated camera: LED spot, motion blur, noise, saturation, and a video OpenCV reads back."""

import cv2
import numpy as np
import pytest

from rig.errors import ConfigError
from rig.writers import VideoRecord
from rig.sim.camera import CameraConfig, CameraSensor

NO_PANEL = (0, 0, 1, 1)


def _centroid(image: np.ndarray, background: float) -> tuple[float, float]:
    light = np.clip(image.astype(float) - background, 0, None)
    light[light < 20] = 0
    ys, xs = np.indices(light.shape) + 0.5
    return float((light * xs).sum() / light.sum()), float((light * ys).sum() / light.sum())


def test_default_exposure_is_the_whole_frame_interval() -> None:
    config = CameraConfig(fps=240.0)
    assert config.exposure == pytest.approx(1 / 240)
    offsets = config.subsample_offsets()
    assert offsets.min() > 0 and offsets.max() < config.exposure
    assert offsets.mean() == pytest.approx(config.exposure / 2)


def test_led_spot_is_centred_on_its_subpixel_position() -> None:
    config = CameraConfig(noise_dn=0.0, led_peak_dn=200.0)
    frame = CameraSensor(config, seed=1).expose(np.array([[100.3, 200.7]]), np.zeros((1, 1)), NO_PANEL)
    x, y = _centroid(frame, config.dark_dn)
    assert x == pytest.approx(100.3, abs=0.05)
    assert y == pytest.approx(200.7, abs=0.05)


def test_bright_led_saturates_at_255() -> None:
    frame = CameraSensor(CameraConfig(noise_dn=0.0), seed=1).expose(np.array([[50.0, 50.0]]), np.zeros((1, 1)), NO_PANEL)
    assert frame.max() == 255
    assert np.count_nonzero(frame == 255) > 4


def test_motion_blur_spreads_the_spot_along_its_path() -> None:
    config = CameraConfig(noise_dn=0.0, led_peak_dn=200.0)
    path = np.column_stack([np.linspace(100, 120, config.subsamples), np.full(config.subsamples, 60.0)])
    frame = CameraSensor(config, seed=1).expose(path, np.zeros((1, 1)), NO_PANEL)
    x, y = _centroid(frame, config.dark_dn)
    assert x == pytest.approx(110.0, abs=0.1)
    lit = np.argwhere(frame > config.dark_dn + 20)
    assert np.ptp(lit[:, 1]) > 3 * np.ptp(lit[:, 0])


def test_led_light_scales_with_its_level_at_each_sub_instant() -> None:
    config = CameraConfig(noise_dn=0.0, dark_dn=0.0, led_peak_dn=200.0, subsamples=4)
    spot = np.array([[60.5, 40.5]] * 4)

    def frame(levels: list[int] | None) -> np.ndarray:
        sensor = CameraSensor(config, seed=1)
        return sensor.expose(spot, np.zeros((1, 1)), NO_PANEL, None if levels is None else np.array(levels)).astype(float)

    full = frame(None)
    assert full.max() == 200
    np.testing.assert_array_equal(frame([255] * 4), full)
    np.testing.assert_array_equal(frame([0] * 4), 0)
    # each pixel, to the rounding of the two 8-bit frames
    assert np.abs(frame([255, 0, 0, 255]) - full / 2).max() <= 0.6
    assert np.abs(frame([51] * 4) - full / 5).max() <= 0.6


def test_a_dark_sub_instant_leaves_no_trail() -> None:
    """The LED moves while it blinks: only where it was lit shows in the frame."""
    config = CameraConfig(noise_dn=0.0, dark_dn=0.0, led_peak_dn=200.0, subsamples=4)
    path = np.column_stack([np.linspace(40.0, 160.0, 4), np.full(4, 60.0)])
    frame = CameraSensor(config, seed=1).expose(path, np.zeros((1, 1)), NO_PANEL, np.array([255, 0, 0, 0]))
    x, _ = _centroid(frame, 0.0)
    assert x == pytest.approx(40.0, abs=0.1)


def test_noise_has_the_configured_spread_around_the_dark_level() -> None:
    config = CameraConfig(noise_dn=3.0, dark_dn=20.0)
    sensor = CameraSensor(config, seed=5)
    frames = np.stack([sensor.expose(np.array([[-100.0, -100.0]]), np.zeros((1, 1)), NO_PANEL) for _ in range(4)])
    assert frames.mean() == pytest.approx(20.0, abs=0.1)
    assert frames.std() == pytest.approx(np.sqrt(3.0**2 + 1 / 12), rel=0.05)


def test_panel_light_lands_in_its_rectangle() -> None:
    config = CameraConfig(noise_dn=0.0, dark_dn=0.0)
    panel = np.full((10, 20), 100.0, dtype=np.float32)
    frame = CameraSensor(config, seed=1).expose(np.array([[-100.0, -100.0]]), panel, (300, 200, 20, 10))
    assert (frame[200:210, 300:320] == 100).all()
    assert frame.sum() == 100 * 200


def test_video_is_read_back_by_opencv(tmp_path) -> None:
    path = tmp_path / "v.avi"
    with VideoRecord(path, fps=240.0, width=160, height=120) as video:
        for i in range(12):
            video.write(np.full((120, 160), 10 * i, dtype=np.uint8))
    capture = cv2.VideoCapture(str(path))
    assert capture.get(cv2.CAP_PROP_FPS) == pytest.approx(240.0)
    levels = []
    while True:
        ok, frame = capture.read()
        if not ok:
            break
        levels.append(frame.mean())
    assert len(levels) == 12
    np.testing.assert_allclose(levels, 10 * np.arange(12), atol=1.5)


@pytest.mark.parametrize("bad", [dict(fps=0.0), dict(exposure_s=0.5), dict(width=10), dict(subsamples=0), dict(noise_dn=-1.0)])
def test_bad_camera_settings_are_rejected(bad: dict) -> None:
    with pytest.raises(ConfigError):
        CameraConfig(**bad)
