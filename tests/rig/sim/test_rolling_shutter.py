"""The simulated camera's rolling shutter: row y of H exposed (y / H) x readout after row 0, for the
LED's spot and for every row of the display panel, and its frame-timing jitter."""

import numpy as np
import pytest

from rig.errors import ConfigError
from rig.sim.camera import CameraConfig, SimCamera
from rig.sim.display import DisplayConfig, SimDisplay
from rig.sim.scene import FilmedScene

WIDTH, HEIGHT = 160, 120
FPS = 120.0
READOUT_S = 8e-3
EXPOSURE_S = 4e-3
SPEED_PX_S = 2000.0
NO_PANEL = (0, 0, 1, 1)


class _LedScene:
    """An LED crossing the frame at a constant speed along row `row`, and nothing else lit."""

    def __init__(self, row: float, speed: float) -> None:
        self.row, self.speed = row, speed
        self.panel = NO_PANEL
        self.layout = type("Layout", (), {"led_roi": (0, 0, WIDTH, HEIGHT), "sphere_roi": NO_PANEL})()
        self.settled_until = np.inf

    def led_pixels(self, instants: np.ndarray) -> np.ndarray:
        return np.stack([30.0 + self.speed * instants, np.full(instants.shape, self.row)], axis=-1)

    def led_levels(self, instants: np.ndarray) -> None:
        return None

    def panel_light(self, starts: np.ndarray, exposure: float) -> np.ndarray:
        return np.zeros((1, 1), dtype=np.float32)


def _camera(scene, readout_s: float = READOUT_S, **changes) -> SimCamera:
    config = CameraConfig(
        fps=FPS, exposure_s=EXPOSURE_S, width=WIDTH, height=HEIGHT, noise_dn=0.0, dark_dn=0.0, led_peak_dn=200.0,
        subsamples=16, readout_s=readout_s, **changes,
    )  # fmt: skip
    camera = SimCamera(config, scene, duration_s=0.1, seed=3, impairment_seed=4)
    camera.connect(None)
    return camera


def _row_centroids(image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each lit row's centroid x (pixel centres at +0.5), and the rows."""
    light = image.astype(float)
    rows = np.flatnonzero(light.sum(axis=1) > 50.0)
    xs = np.arange(WIDTH) + 0.5
    return rows, (light[rows] * xs).sum(axis=1) / light[rows].sum(axis=1)


def test_a_static_led_is_not_skewed() -> None:
    frame = _camera(_LedScene(row=60.0, speed=0.0)).poll()[2]
    rows, centroids = _row_centroids(frame.image)
    assert len(rows) >= 8
    assert np.ptp(centroids) < 1e-2


def test_a_moving_led_is_skewed_by_its_speed_times_the_readout_per_row() -> None:
    """Each row sees the spot where it was during that row's own exposure: x moves v R / H a row."""
    frame = _camera(_LedScene(row=60.0, speed=SPEED_PX_S)).poll()[2]
    rows, centroids = _row_centroids(frame.image)
    slope = np.polyfit(rows, centroids, 1)[0]
    assert slope == pytest.approx(SPEED_PX_S * READOUT_S / HEIGHT, rel=0.02)


@pytest.mark.parametrize("row", [20.5, 60.5, 100.5])
def test_the_leds_timing_shifts_with_its_row_by_the_readout(row: float) -> None:
    """The spot's centroid is where the LED was at the middle of its rows' exposure:
    t + (y / H) readout + exposure / 2, to the 8-bit image's rounding (0.02 px, 10 us at this speed;
    half a row's readout, a row counted from its centre instead of its index, is 33 us)."""
    frame = _camera(_LedScene(row=row, speed=SPEED_PX_S)).poll()[2]
    light = frame.image.astype(float)
    x = (light * (np.arange(WIDTH) + 0.5)).sum() / light.sum()
    seen_at = (x - 30.0) / SPEED_PX_S
    assert frame.readout_s == READOUT_S
    assert seen_at - frame.t_start - EXPOSURE_S / 2 == pytest.approx((row - 0.5) / HEIGHT * READOUT_S, abs=1e-5)
    assert frame.row_start(row - 0.5) == pytest.approx(frame.t_start + (row - 0.5) / HEIGHT * READOUT_S)


def test_each_panel_row_integrates_the_display_over_its_own_exposure() -> None:
    """A display turning white at one refresh: each panel row shows the share of its own exposure
    after the switch reached it (the display's scan-out, then the camera's readout), exactly."""
    display = SimDisplay(DisplayConfig(refresh_hz=60.0, width=32, height=24, scanout_fraction=0.5))
    white = np.full((24, 32, 3), 255, dtype=np.uint8)
    display.present(white, t_ready=0.004, image_id=0)
    for k in range(8):
        display.shown(k)
    layout = type("Layout", (), {"panel": (40, 10, 64, 48), "led_roi": (0, 0, 8, 8), "sphere_roi": (40, 10, 64, 48)})()
    scene = FilmedScene(None, display, layout, display_black_dn=0.0, display_white_dn=200.0, board=None)
    config = CameraConfig(fps=FPS, exposure_s=EXPOSURE_S, width=WIDTH, height=HEIGHT, readout_s=READOUT_S)
    rows = 10 + np.arange(48)
    starts = 0.0145 + config.row_delays(rows)
    light = scene.panel_light(starts, EXPOSURE_S)[:, 0]
    switch = 1 / 60.0 + (np.arange(48) + 0.5) / 48 * 0.5 / 60.0
    expected = 200.0 * np.clip((starts + EXPOSURE_S - switch) / EXPOSURE_S, 0.0, 1.0)
    np.testing.assert_allclose(light, expected, atol=1e-3)
    assert 0 < np.count_nonzero((expected > 0) & (expected < 200))


def test_frame_jitter_moves_each_exposure_but_the_first_within_half_the_jitter() -> None:
    jitter = 2e-3
    camera = _camera(_LedScene(row=60.0, speed=0.0), readout_s=0.0, frame_jitter_s=jitter, container="mp4", codec="h264")
    shift = camera.frame_times - np.arange(len(camera.frame_times)) / FPS
    assert shift[0] == 0.0
    assert np.abs(shift).max() <= jitter / 2 and np.std(shift[1:]) > jitter / 5
    again = _camera(_LedScene(row=60.0, speed=0.0), readout_s=0.0, frame_jitter_s=jitter, container="mp4", codec="h264")
    np.testing.assert_array_equal(camera.frame_times, again.frame_times)


@pytest.mark.parametrize(
    ("bad", "message"),
    [
        (dict(readout_s=-1e-3), "readout"),
        (dict(readout_s=9e-3), "readout"),
        (dict(frame_jitter_s=1e-3, container="mp4", codec="h264"), "jitter"),
        (dict(exposure_s=4e-3, readout_s=5e-3, frame_jitter_s=4e-3, container="mp4", codec="h264"), "jitter"),
        (dict(exposure_s=4e-3, frame_jitter_s=1e-3), "mp4 or mov"),
        (dict(container="mp4", codec="mjpeg"), "not written here"),
        (dict(container="mkv"), "container"),
    ],
)
def test_impossible_shutters_and_films_are_refused(bad: dict, message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        CameraConfig(fps=FPS, **bad)
