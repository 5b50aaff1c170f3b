"""The swing's start and stop: departures from rest, and the whole number of periods they fix."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import analysis
from analysis.onset import departure_time, stop_time

FPS = 240.0


def released(t: np.ndarray, release_s: float, amplitude: float, period_s: float = 0.8) -> np.ndarray:
    """Distance along the swing of a pendulum held at +amplitude and released from rest at release_s."""
    since = np.maximum(t - release_s, 0.0)
    return amplitude * np.exp(-0.1 * since) * np.cos(2 * math.pi / period_s * since)


def test_departures_of_two_released_swings_lie_the_latency_apart_whatever_their_size():
    rng = np.random.default_rng(1)
    t = np.arange(0, 4, 1 / FPS)
    led = released(t, 0.7, 120.0) + 0.05 * rng.standard_normal(t.size)
    sphere = 300 + released(t, 0.7 + 0.4321, -35.0) + 0.2 * rng.standard_normal(t.size)
    lag = departure_time(t, sphere, np.full_like(t, 50.0)) - departure_time(t, led, np.zeros_like(t))
    assert lag == pytest.approx(0.4321, abs=1e-3)


def test_no_departure_when_the_clip_starts_mid_swing():
    t = np.arange(0, 4, 1 / FPS)
    assert departure_time(t, released(t, -0.3, 100.0), np.zeros_like(t)) is None


def test_no_departure_when_it_never_moves():
    t = np.arange(0, 2, 1 / FPS)
    assert departure_time(t, np.full_like(t, 3.0), np.zeros_like(t)) is None


def test_departure_is_found_through_the_missing_frames_of_a_blinking_led():
    t = np.arange(0, 3, 1 / FPS)
    x = released(t, 1.2, 80.0)
    blinking = (t < 1.0) & (np.floor(t / 0.05) % 3 == 0)
    x[blinking] = np.nan
    y = np.where(np.isfinite(x), 0.0, np.nan)
    assert departure_time(t, x, y) == pytest.approx(departure_time(t, released(t, 1.2, 80.0), np.zeros_like(t)), abs=1e-4)


def test_a_pendulum_stopped_dead_stops_the_latency_apart_on_both_tracks():
    t = np.arange(0, 4, 1 / FPS)
    led = released(t, -1.0, 100.0)
    led[t > 3.1] = led[np.searchsorted(t, 3.1)]
    sphere = released(t - 0.25, -1.0, 40.0)
    sphere[t > 3.35] = sphere[np.searchsorted(t, 3.35)]
    zeros = np.zeros_like(t)
    assert departure_time(t, led, zeros) is None
    assert stop_time(t, sphere, zeros) - stop_time(t, led, zeros) == pytest.approx(0.25, abs=2 / FPS)


@given(st.floats(0.1, 50.0), st.floats(-500.0, 500.0), st.floats(-100.0, 100.0), st.floats(-10.0, 10.0))
def test_departure_moves_with_time_and_ignores_scale_and_position(scale, dx, dy, shift):
    t = np.arange(0, 2.5, 1 / FPS)
    x = released(t, 1.0, 10.0)
    zeros = np.zeros_like(t)
    base = departure_time(t, x, zeros)
    moved = departure_time(t + shift, scale * x + dx, zeros + dy)
    assert moved == pytest.approx(base + shift, abs=1e-6)


@pytest.mark.parametrize(
    ("latency_s", "release_s", "stop_s", "how"),
    [(0.8, 1.0, None, "swing start"), (0.45, None, 5.0, "swing stop"), (0.05, 0.5, 5.5, "swing start+swing stop")],
)
def test_a_video_of_the_release_or_the_stop_fixes_latencies_a_period_apart(scene, render_video, latency_s, release_s, stop_s, how):
    """Period 0.6 s, latencies from -200 to 1000 ms allowed: two candidates, too little chirp to tell."""
    video = scene(latency_s=latency_s, period_s=0.6, duration_s=7.0, release_s=release_s, stop_s=stop_s)
    result = analysis.analyse(render_video(video), analysis.AnalysisOptions(fps=video.fps, latency_range_ms=(-200, 1000)))
    assert result.cycles.how == how and not result.ambiguous
    assert result.latency_ms == pytest.approx(latency_s * 1e3, abs=0.3)
    for lag in result.cycles.events_s.values():
        assert lag == pytest.approx(latency_s, abs=0.01)
    begin, end = result.diagnostics["swinging_s"]
    if release_s is not None:
        assert begin >= release_s + latency_s
    if stop_s is not None:
        assert end <= stop_s


def test_without_the_release_the_same_video_is_ambiguous(scene, render_video):
    video = scene(latency_s=0.8, period_s=0.6, duration_s=7.0, release_s=None)
    result = analysis.analyse(render_video(video), analysis.AnalysisOptions(fps=video.fps, latency_range_ms=(-200, 1000)))
    assert result.ambiguous and result.cycles.events_s == {}
