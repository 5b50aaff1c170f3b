"""A rolling shutter films each blob when the readout reaches its rows: given the readout, every
estimator times each blob by its own rows; without it, the interval reaches out by the largest bias
the rows allow, on the side the truth lies, with a warning.

The tracks are exact: a damped swing sampled, frame by frame, at the frame time plus the blob's row
/ H x readout, as a rolling-shutter camera films it. The display is 60 Hz and the camera exposes
its whole frame interval at 240 or 30 fps, exposures that tile each refresh, so its sampling of the
display biases nothing and every difference below is the shutter's.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from analysis import AnalysisError, AnalysisOptions, Tracks, estimate
from analysis.timing import FrameTimes
from analysis.blobs import Roi, Track

FPS = 240.0
HEIGHT = 480
LATENCY_S = 0.0427
PERIOD_S = 0.8
SECONDS = 6.0


def told(fps: float = FPS, **options) -> AnalysisOptions:
    """The settings the sampling needs told, as a lab that knows them says (see the module docstring),
    and ``options``."""
    return AnalysisOptions(display_hz=60.0, exposure_ms=1e3 / fps, **options)


def swing_x(t: np.ndarray) -> np.ndarray:
    return 150.0 * np.exp(-0.05 * t) * np.sin(2 * math.pi * t / PERIOD_S + 0.3)


def filmed(x_of_t, rows_of_t, readout_s: float, seed: int, fps: float) -> Track:
    """A blob at x_of_t(t), on rows rows_of_t(t), filmed by the rolling shutter: each frame sees it
    at the frame time plus its row / HEIGHT x readout (found by iterating, the row itself moving)."""
    frames = np.arange(round(SECONDS * fps)) / fps
    seen = frames.copy()
    for _ in range(4):
        seen = frames + rows_of_t(seen) / HEIGHT * readout_s
    rng = np.random.default_rng(seed)
    x = x_of_t(seen) + 0.02 * rng.standard_normal(frames.size)
    y = rows_of_t(seen)
    count = frames.size
    return Track(frames, x, y, np.ones(count, dtype=bool), np.full(count, 200.0), np.zeros(count, dtype=bool))


def tracks_of(led_rows, sphere_rows, readout_s: float, fps: float = FPS) -> Tracks:
    """Tracks of an LED and a sphere LATENCY_S behind it, on the rows given (functions of time)."""
    led = filmed(lambda t: 320.0 + swing_x(t), led_rows, readout_s, 1, fps)
    sphere = filmed(lambda t: 960.0 + 0.8 * swing_x(t - LATENCY_S), sphere_rows, readout_s, 2, fps)
    times = FrameTimes(led.t, fps, "frame rate given", 0, False, [])
    roi = Roi(0, 0, 10, 10)
    return Tracks(led, sphere, led.t, times, roi, roi, "given", "given", (), {}, 0.0, (1280, HEIGHT))


def constant(row: float):
    return lambda t: np.full(np.shape(t), row)


LED_ROW, SPHERE_ROW = 120.0, 288.0  # the sphere 35 % of the frame below the LED
READOUT_S = 3.5e-3
SHORT_S = (SPHERE_ROW - LED_ROW) / HEIGHT * READOUT_S  # what the frame times read short


# A 30 fps webcam reading out in 25 ms dates the sphere 8.75 ms after the LED, a quarter of a frame
# off the grid the phase and correlation methods interpolate onto.
@pytest.mark.parametrize(("fps", "readout_s"), [(FPS, READOUT_S), (30.0, 25e-3)])
def test_with_the_readout_given_every_estimator_times_each_blob_by_its_rows(fps: float, readout_s: float) -> None:
    tracks = tracks_of(constant(LED_ROW), constant(SPHERE_ROW), readout_s, fps)
    result = estimate(tracks, told(fps, method="all", readout_ms=readout_s * 1e3))
    for name, method in result.methods.items():
        # The correlation's peak between samples is good to about 0.15 ms at 30 fps, shutter or not.
        assert method.latency_ms == pytest.approx(LATENCY_S * 1e3, abs=0.2 if name == "xcorr" else 0.01), name
        if method.ci95_ms is not None:
            assert method.ci95_ms[0] <= LATENCY_S * 1e3 <= method.ci95_ms[1], name
            assert method.ci95_ms[1] - method.ci95_ms[0] < 0.2, name
    assert result.warnings == []
    np.testing.assert_allclose(result.sphere_track.t - tracks.sphere.t, SPHERE_ROW / HEIGHT * readout_s)
    np.testing.assert_allclose(result.led_track.t - tracks.led.t, LED_ROW / HEIGHT * readout_s)


def test_without_the_readout_the_interval_reaches_later_by_what_the_rows_allow() -> None:
    tracks = tracks_of(constant(LED_ROW), constant(SPHERE_ROW), READOUT_S)
    framed = estimate(tracks, told(readout_ms=0.0))  # the frame times taken as the truth's
    result = estimate(tracks, told())
    truth_ms = LATENCY_S * 1e3
    assert result.latency_ms == pytest.approx(truth_ms - SHORT_S * 1e3, abs=0.02)
    assert framed.ci95_ms[1] < truth_ms  # not widened, the interval misses the truth
    bound_ms = (SPHERE_ROW - LED_ROW) / HEIGHT * 1e3 / FPS  # the rows' difference over a whole frame interval
    assert result.ci95_ms[0] == pytest.approx(framed.ci95_ms[0], abs=1e-9)
    assert result.ci95_ms[1] == pytest.approx(framed.ci95_ms[1] + bound_ms, abs=1e-3)
    assert result.ci95_ms[0] <= truth_ms <= result.ci95_ms[1]
    (warning,) = result.warnings
    assert warning.startswith("the sphere sits 168 rows below the LED")
    cause, remedy = warning.split("\n")
    assert "rolling shutter" in cause and "longer than measured" in cause and remedy.startswith("to avoid it: ")
    for way in ("film the LED at the sphere's height", "--readout-ms", "rig calibrate-camera"):
        assert way in remedy
    summary = result.to_dict()["rolling_shutter"]
    assert summary["readout_source"] == "bounded" and summary["readout_ms"] == pytest.approx(1e3 / FPS)
    assert (summary["led_row"], summary["sphere_row"]) == (pytest.approx(LED_ROW), pytest.approx(SPHERE_ROW))
    assert summary["bias_bound_ms"] == pytest.approx(bound_ms)


def test_a_sphere_above_the_led_widens_the_interval_towards_shorter_latencies() -> None:
    tracks = tracks_of(constant(SPHERE_ROW), constant(LED_ROW), READOUT_S)
    framed = estimate(tracks, told(readout_ms=0.0))
    result = estimate(tracks, told())
    assert result.latency_ms == pytest.approx(LATENCY_S * 1e3 + SHORT_S * 1e3, abs=0.02)
    assert result.ci95_ms[1] == pytest.approx(framed.ci95_ms[1], abs=1e-9)
    assert result.ci95_ms[0] < LATENCY_S * 1e3 < framed.ci95_ms[0]
    assert "rows above the LED" in result.warnings[0] and "shorter than measured" in result.warnings[0]


def test_blobs_on_the_same_rows_need_no_readout() -> None:
    tracks = tracks_of(constant(200.0), constant(200.3), READOUT_S)
    result = estimate(tracks, told())
    assert result.warnings == []
    assert result.latency_ms == pytest.approx(LATENCY_S * 1e3, abs=0.02)
    assert result.to_dict()["rolling_shutter"]["bias_bound_ms"] == pytest.approx(0.3 / HEIGHT * 1e3 / FPS, rel=0.01)


def test_rows_that_change_with_the_swing_are_dated_frame_by_frame() -> None:
    # The display is tilted in the image: the sphere's row follows its swing, 60 rows up and down.
    def sphere_rows(t: np.ndarray) -> np.ndarray:
        return SPHERE_ROW + 0.4 * swing_x(t - LATENCY_S)

    tracks = tracks_of(constant(LED_ROW), sphere_rows, READOUT_S)
    result = estimate(tracks, told(method="all", readout_ms=READOUT_S * 1e3))
    for name, method in result.methods.items():
        assert method.latency_ms == pytest.approx(LATENCY_S * 1e3, abs=0.02), name
    np.testing.assert_allclose(result.sphere_track.t - tracks.sphere.t, tracks.sphere.y / HEIGHT * READOUT_S)


def test_the_board_reference_reads_the_led_at_its_own_times() -> None:
    tracks = tracks_of(constant(LED_ROW), constant(SPHERE_ROW), READOUT_S)
    seen = []

    def departures(led: Track) -> dict[str, float]:
        seen.append(led.t)
        return {}

    estimate(tracks, told(readout_ms=READOUT_S * 1e3), reference_departures=departures)
    np.testing.assert_allclose(seen[0], tracks.led.t + LED_ROW / HEIGHT * READOUT_S)


@pytest.mark.parametrize("readout_ms", [-1.0, math.nan, math.inf])
def test_a_readout_that_is_no_time_is_refused(readout_ms: float) -> None:
    with pytest.raises(AnalysisError, match="readout_ms must be a number of ms from 0 to 1000"):
        AnalysisOptions(readout_ms=readout_ms)


def test_a_readout_longer_than_a_frame_is_refused() -> None:
    tracks = tracks_of(constant(LED_ROW), constant(SPHERE_ROW), READOUT_S)
    with pytest.raises(AnalysisError, match="longer than the frame interval"):
        estimate(tracks, AnalysisOptions(readout_ms=5.0))
