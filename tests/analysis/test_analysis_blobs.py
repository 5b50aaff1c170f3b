"""Blob tracking and ROI detection against known blob positions."""

import dataclasses
import math

import numpy as np
import pytest

from analysis.errors import AnalysisError
from analysis.blobs import WINDOW_MARGIN_PX, BlobModel, BlobTracker, Roi, calibrate_blob, find_moving_regions

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


def locate(model, frame):
    """The blob found in one frame by a fresh tracker (a whole-ROI search)."""
    detection = BlobTracker(model).locate(frame)
    return detection.x, detection.y, detection.peak, detection.valid


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
    found = np.array([locate(model, frame) for frame in frames])
    assert found[:, 3].all()
    error = np.hypot(found[:, 0] - xs, found[:, 1] - ys)
    # Noise of one unit on every pixel of the box moves a single centroid by a few hundredths...
    assert np.sqrt(np.mean(error**2)) < 0.06
    assert error.max() < 0.15
    # ...but not on average: no pull towards pixel centres or the window.
    assert abs(np.mean(found[:, 0] - xs)) < 0.015
    assert abs(np.mean(found[:, 1] - ys)) < 0.015


def test_double_image_of_a_refresh_gives_the_weighted_position():
    # A sphere that jumps during the exposure shows two images; the linear centroid must weight
    # them by their exposure (a halfway threshold would keep only the brighter and be 1.8 px off).
    _, _, frames = sweep(150.0)
    model = calibrate_blob(FULL, frames, "sphere")
    double = frames_of([0.7 * gaussian(30.0, 24.0, 150.0) + 0.3 * gaussian(36.0, 24.0, 150.0)], seed=3)[0]
    x, y, _, valid = locate(model, double)
    assert valid
    assert x == pytest.approx(0.7 * 30.0 + 0.3 * 36.0, abs=0.2)
    assert y == pytest.approx(24.0, abs=0.1)


def test_frame_without_blob_is_invalid():
    _, _, frames = sweep(150.0)
    model = calibrate_blob(FULL, frames, "sphere")
    x, y, _, valid = locate(model, frames_of([np.zeros((HEIGHT, WIDTH))], seed=5)[0])
    assert not valid
    assert math.isnan(x) and math.isnan(y)


def test_blob_is_located_in_frame_coordinates_from_an_roi():
    xs, ys, frames = sweep(150.0)
    roi = Roi(3, 10, 58, 25)
    model = calibrate_blob(roi, frames, "LED")
    x, y, _, valid = locate(model, frames[20])
    assert valid
    assert (x, y) == pytest.approx((xs[20], ys[20]), abs=0.05)


def test_roi_without_a_moving_blob_raises():
    frames = frames_of([np.zeros((HEIGHT, WIDTH))] * 30)
    with pytest.raises(AnalysisError, match="no moving blob"):
        calibrate_blob(FULL, frames, "LED")


def test_tracker_follows_the_blob_in_a_window_and_finds_it_again_after_losing_it():
    xs, ys, frames = sweep(150.0)
    model = calibrate_blob(FULL, frames, "LED")
    tracker = BlobTracker(model)
    empty = frames_of([np.zeros((HEIGHT, WIDTH))], seed=9)[0]
    sequence = frames[:20] + [empty, empty] + frames[20:]
    found = [tracker.locate(frame) for frame in sequence]
    valid = np.array([d.valid for d in found])
    assert valid.tolist() == [True] * 20 + [False, False] + [True] * 21
    x = np.array([d.x for d in found])[valid]
    assert x == pytest.approx(xs, abs=0.1)


def test_static_bright_clutter_is_background_and_never_the_blob():
    xs, ys, _ = sweep(150.0)
    lamp = gaussian(50.0, 40.0, 240.0, sigma=2.5)
    frames = frames_of([gaussian(x, y, 150.0) + lamp for x, y in zip(xs, ys, strict=True)])
    model = calibrate_blob(FULL, frames, "LED")
    tracker = BlobTracker(model)
    found = np.array([(d.x, d.y) for d in (tracker.locate(f) for f in frames)])
    assert found[:, 0] == pytest.approx(xs, abs=0.1)
    assert found[:, 1] == pytest.approx(ys, abs=0.1)


def test_blob_cut_by_the_roi_edge_is_clipped_not_valid():
    xs, ys, frames = sweep(150.0)
    roi = Roi(20, 0, 44, HEIGHT)
    model = calibrate_blob(roi, frames, "sphere")
    tracker = BlobTracker(model)
    found = [tracker.locate(frame) for frame in frames]
    clipped = np.array([d.clipped for d in found])
    near_edge = xs < 20 + 5
    assert clipped[near_edge & (xs > 20 - 2)].all()
    assert not clipped[xs > 30].any()
    assert all(d.valid for d, far in zip(found, xs > 30, strict=True) if far)


def _contains(roi: Roi, x: np.ndarray, y: np.ndarray, margin: float) -> bool:
    return bool(
        (x - margin >= roi.x).all()
        and (x + margin <= roi.x + roi.width).all()
        and (y - margin >= roi.y).all()
        and (y + margin <= roi.y + roi.height).all()
    )


@pytest.mark.parametrize("sphere_gain", [150.0, 25.0], ids=["bright", "dim"])
def test_moving_regions_enclose_the_led_and_the_sphere(scene, render_video, scene_truth, sphere_gain):
    clip = scene(duration_s=2.5, display_hz=60.0, sphere_gain=sphere_gain)
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


def test_static_clutter_is_not_a_moving_region(scene, render_video):
    clip = scene(duration_s=2.5, clutter=((60.0, 20.0, 400.0), (120.0, 100.0, 300.0)))
    regions = find_moving_regions(list(render_video(clip)[: int(1.5 * clip.fps)]))
    assert len(regions) == 2


def test_double_image_in_two_separate_pieces_gives_the_weighted_position():
    # Sharp images 9 px apart do not touch above the threshold: both pieces reach twice the
    # threshold, so both count, each by its exposure.
    xs, ys, _ = sweep(150.0)
    sharp = frames_of([gaussian(x, y, 150.0, sigma=1.5) for x, y in zip(xs, ys, strict=True)])
    model = calibrate_blob(FULL, sharp, "sphere")
    images = 0.6 * gaussian(27.0, 24.0, 150.0, sigma=1.5) + 0.4 * gaussian(36.0, 24.0, 150.0, sigma=1.5)
    double = frames_of([images], seed=4)[0]
    x, y, _, valid = locate(model, double)
    assert valid
    assert x == pytest.approx(0.6 * 27.0 + 0.4 * 36.0, abs=0.1)
    assert y == pytest.approx(24.0, abs=0.1)


def test_faint_speck_apart_from_the_blob_is_not_part_of_it():
    # A 2x2 speck above the threshold but never reaching twice it, 9 px from the blob: counted, it
    # would pull the centroid by about 0.2 px.
    _, _, frames = sweep(150.0)
    model = calibrate_blob(FULL, frames, "sphere")
    blob = gaussian(30.0, 24.0, 150.0)
    speck = np.zeros_like(blob)
    speck[23:25, 39:41] = 1.5 * model.threshold
    alone, beside = frames_of([blob], seed=6)[0], frames_of([blob + speck], seed=6)[0]
    x, y, _, valid = locate(model, beside)
    assert valid
    assert (x, y) == pytest.approx(locate(model, alone)[:2], abs=0.04)
    assert (x, y) == pytest.approx((30.0, 24.0), abs=0.1)


def test_8bit_frames_are_located_exactly_as_their_float_copies():
    # 8-bit frames take an integer path (int16 differences); it must give what float arithmetic gives.
    _, _, frames = sweep(150.0)
    model = calibrate_blob(FULL, frames, "sphere")
    float_model = dataclasses.replace(model, background=model.background.astype(np.float32))
    extra = [gaussian(30.0, 24.0, 150.0) + 0.5 * gaussian(37.0, 24.0, 150.0), np.zeros((HEIGHT, WIDTH))]
    sequence = frames + frames_of(extra, seed=8) + frames[::-1]
    tracker, float_tracker = BlobTracker(model), BlobTracker(float_model)
    found = [tracker.locate(frame) for frame in sequence]
    float_found = [float_tracker.locate(frame.astype(np.float32)) for frame in sequence]
    found, float_found = np.array(found, dtype=float), np.array(float_found, dtype=float)
    # Positions, peaks and masses agree exactly; second moments to the last few bits (OpenCV sums
    # integer and float pixels in different orders).
    assert np.array_equal(found[:, :7], float_found[:, :7], equal_nan=True)
    np.testing.assert_allclose(found[:, 7:], float_found[:, 7:], rtol=1e-12, atol=1e-12)


def test_a_window_whose_signed_weights_sum_to_nothing_holds_no_blob():
    """One hot pixel in a frame darker than the background everywhere else: the centroid's mass,
    over the support around it, is negative, so there is no position to give."""
    background = np.full((40, 40), 100, dtype=np.uint8)
    model = BlobModel(Roi(0, 0, 40, 40), background, threshold=20.0, min_peak=60.0, typical_peak=150.0, reach=3.0)
    frame = np.full((40, 40), 50, dtype=np.uint8)
    frame[20, 20] = 255
    detection = BlobTracker(model).locate(frame)
    assert not detection.valid and math.isnan(detection.x)


def test_a_tracker_given_cropped_frames_finds_what_it_finds_in_whole_frames():
    # After calibration the analyser decodes only the rectangle around both ROIs; a tracker told
    # the rectangle's origin must give the same frame coordinates, bit for bit.
    _, _, frames = sweep(150.0)
    model = calibrate_blob(Roi(10, 5, 50, 40), frames, "sphere")
    whole, cropped = BlobTracker(model), BlobTracker(model, origin=(7, 3))
    found = [whole.locate(frame) for frame in frames]
    found_cropped = [cropped.locate(frame[3:47, 7:62]) for frame in frames]
    assert sum(d.valid for d in found) > len(frames) // 2
    assert np.array_equal(np.array(found, dtype=float), np.array(found_cropped, dtype=float), equal_nan=True)


def test_a_sphere_that_jumps_between_held_frames_keeps_both_images_of_the_jump():
    """A display holding each pose for several refreshes shows the sphere still, then jumps it
    farther than the tracker's window around a still blob. In a frame exposed across the jump the
    camera sees both images, and the centroid must weight both (linear in the switch time); missing
    the new one delays every switch, which read as a millisecond of latency on the simulated rig."""
    _, _, calibration = sweep(150.0)
    model = calibrate_blob(FULL, calibration, "sphere")
    old, new = 28.0, 44.0
    held = [gaussian(12.0, 24.0, 150.0)] * 4 + [gaussian(old, 24.0, 150.0)] * 4
    straddling = 0.6 * gaussian(old, 24.0, 150.0) + 0.4 * gaussian(new, 24.0, 150.0)
    assert new - old > model.reach + WINDOW_MARGIN_PX
    tracker = BlobTracker(model)
    found = [tracker.locate(frame) for frame in frames_of([*held, straddling], seed=9)]
    assert all(d.valid for d in found)
    assert found[-1].x == pytest.approx(0.6 * old + 0.4 * new, abs=0.15)
