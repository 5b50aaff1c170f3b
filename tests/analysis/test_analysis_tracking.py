"""Blob tracking and ROI detection against known blob positions."""

import math

import numpy as np
import pytest

from analysis.errors import AnalysisError
from analysis.tracking import Roi, calibrate_blob, find_moving_regions, locate_blob, track_blobs

WIDTH, HEIGHT = 64, 48


def gaussian(x: float, y: float, peak: float, sigma: float = 2.0) -> np.ndarray:
    cols, rows = np.meshgrid(np.arange(WIDTH), np.arange(HEIGHT))
    return peak * np.exp(-((cols - x) ** 2 + (rows - y) ** 2) / (2 * sigma**2))


def frames_of(images: list[np.ndarray], noise: float = 1.0, seed: int = 0) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return [
        np.clip(np.rint(15 + image + noise * rng.standard_normal(image.shape)), 0, 255).astype(np.uint8)
        for image in images
    ]


def sweep(peak: float) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """A blob crossing the frame at sub-pixel steps, and its true centres."""
    xs = np.linspace(8.0, 55.0, 41) + 0.137
    ys = 20.0 + 4 * np.sin(xs / 7)
    return xs, ys, frames_of([gaussian(x, y, peak) for x, y in zip(xs, ys, strict=True)])


FULL = Roi(0, 0, WIDTH, HEIGHT)


@pytest.mark.parametrize("peak", [120.0, 700.0], ids=["dim", "saturated"])
def test_centroid_is_sub_pixel_accurate(peak):
    xs, ys, frames = sweep(peak)
    model = calibrate_blob(FULL, frames, "LED")
    found = np.array([locate_blob(model, frame) for frame in frames])
    assert found[:, 3].all()
    error = np.hypot(found[:, 0] - xs, found[:, 1] - ys)
    assert np.sqrt(np.mean(error**2)) < 0.04
    assert error.max() < 0.1


def test_double_image_of_a_refresh_gives_the_weighted_position():
    # A sphere that jumps during the exposure shows two images; the linear centroid must weight
    # them by their exposure (a halfway threshold would keep only the brighter and be 1.8 px off).
    _, _, frames = sweep(150.0)
    model = calibrate_blob(FULL, frames, "sphere")
    double = frames_of([0.7 * gaussian(30.0, 24.0, 150.0) + 0.3 * gaussian(36.0, 24.0, 150.0)], seed=3)[0]
    x, y, _, valid = locate_blob(model, double)
    assert valid
    assert x == pytest.approx(0.7 * 30.0 + 0.3 * 36.0, abs=0.2)
    assert y == pytest.approx(24.0, abs=0.05)


def test_frame_without_blob_is_invalid():
    _, _, frames = sweep(150.0)
    model = calibrate_blob(FULL, frames, "sphere")
    x, y, _, valid = locate_blob(model, frames_of([np.zeros((HEIGHT, WIDTH))], seed=5)[0])
    assert not valid
    assert math.isnan(x) and math.isnan(y)


def test_blob_is_located_in_frame_coordinates_from_an_roi():
    xs, ys, frames = sweep(150.0)
    roi = Roi(3, 10, 58, 25)
    model = calibrate_blob(roi, frames, "LED")
    x, y, _, valid = locate_blob(model, frames[20])
    assert valid
    assert (x, y) == pytest.approx((xs[20], ys[20]), abs=0.05)


def test_roi_without_a_moving_blob_raises():
    frames = frames_of([np.zeros((HEIGHT, WIDTH))] * 30)
    with pytest.raises(AnalysisError, match="no moving blob"):
        calibrate_blob(FULL, frames, "LED")


def test_tracks_hold_every_frame_and_report_progress():
    xs, _, frames = sweep(150.0)
    model = calibrate_blob(FULL, frames, "LED")
    calls = []
    (track,) = track_blobs(
        frames * 4, [model], 50.0, len(frames) * 4, lambda done, total: calls.append((done, total))
    )
    assert track.t == pytest.approx(np.arange(len(frames) * 4) / 50.0)
    assert track.x == pytest.approx(np.tile(xs, 4), abs=0.05)
    assert track.valid.all()
    assert calls[0] == (64, 164)
    assert calls[-1] == (164, 164)
    assert [done for done, _ in calls] == sorted(done for done, _ in calls)


def _contains(roi: Roi, x: np.ndarray, y: np.ndarray, margin: float) -> bool:
    return bool(
        (x - margin >= roi.x).all()
        and (x + margin <= roi.x + roi.width).all()
        and (y - margin >= roi.y).all()
        and (y + margin <= roi.y + roi.height).all()
    )


def test_moving_regions_enclose_the_led_and_the_sphere(scene, render_video, scene_truth):
    clip = scene(duration_s=2.5, display_hz=60.0)
    frames = render_video(clip)
    regions = find_moving_regions(list(frames[: int(1.5 * clip.fps)]))
    assert len(regions) == 2
    led_x, led_y, sphere_x, sphere_y = scene_truth(clip)
    led_roi, sphere_roi = sorted(regions, key=lambda roi: roi.x)
    assert _contains(led_roi, led_x, led_y, 2 * clip.led_sigma)
    assert _contains(sphere_roi, sphere_x, sphere_y, 2 * clip.sphere_sigma)


def test_static_scene_has_no_moving_regions():
    assert find_moving_regions(frames_of([gaussian(30.0, 20.0, 200.0)] * 40)) == []


@pytest.mark.parametrize(
    "values",
    [
        [-1, 0, 10, 10],
        [0, 0, 65, 10],
        [60, 40, 5, 9],
        [0, 0, 0, 10],
        [0, 0, 10, -3],
        [1.5, 0, 10, 10],
        [0, 0, 10],
        ["a", 0, 1, 1],
    ],
    ids=["left", "right", "bottom", "no width", "negative height", "fraction", "three numbers", "text"],
)
def test_bad_roi_is_refused(values):
    with pytest.raises(AnalysisError, match="LED ROI"):
        Roi.parse(values, (WIDTH, HEIGHT), "LED")


def test_roi_at_the_frame_edge_is_accepted():
    assert Roi.parse(np.array([4, 8, 60, 40]), (WIDTH, HEIGHT), "LED").as_list() == [4, 8, 60, 40]
