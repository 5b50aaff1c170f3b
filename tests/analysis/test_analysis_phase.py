"""Steed's phase method on signals with known delay: sines, damped swings, held display frames."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from analysis.errors import AnalysisError
from analysis.phase import estimate_frequency, fft_phase_latency, wrap_phase
from analysis.signals import SwingSignals, axis_signal, binned, main_axis
from analysis.blobs import Track


def damped_sine(t: np.ndarray, period: float, phase: float, decay: float, duration: float) -> np.ndarray:
    damping = -math.log(1 - decay) / duration
    return np.exp(-damping * t) * np.sin(2 * math.pi * t / period + phase)


def test_pure_sine_with_a_fraction_of_a_period_is_exact():
    # 2.37 periods: the plain FFT-bin phase is 12 ms off here, the windowed DTFT at the refined
    # frequency 0.3 ms; with the Gram correction the result is exact.
    fps, period, latency = 240.0, 1.1, 0.137
    t = np.arange(int(2.37 * period * fps)) / fps
    led = np.sin(2 * math.pi * t / period + 0.3)
    sphere = np.sin(2 * math.pi * (t - latency) / period + 0.3)
    estimate = fft_phase_latency(led, sphere, fps)
    assert estimate.latency_s == pytest.approx(latency, abs=1e-7)
    assert estimate.frequency_hz == pytest.approx(1 / period, rel=1e-7)
    assert estimate.cycles == pytest.approx(t.size / fps / period, rel=1e-7)


def test_frequency_is_refined_far_below_the_fft_bin():
    fps, period = 120.0, 0.93
    t = np.arange(int(7.3 * period * fps)) / fps
    signal = damped_sine(t, period, 1.0, 0.2, t[-1])
    bin_hz = fps / t.size
    assert abs(estimate_frequency(signal, fps) - 1 / period) < 1e-3 * bin_hz


@pytest.mark.parametrize("fps", [120.0, 240.0])
@pytest.mark.parametrize("display_hz", [60.0, 144.0])
@pytest.mark.parametrize("period", [0.8, 1.3])
@pytest.mark.parametrize("latency", [0.0, 0.0167, 0.05, 0.12, -0.04])
def test_damped_swing_seen_through_a_held_display(scene, camera_signals, fps, display_hz, period, latency):
    led, sphere = camera_signals(
        scene(latency_s=latency, period_s=period, fps=fps, display_hz=display_hz, duration_s=10.3, decay=0.2)
    )
    estimate = fft_phase_latency(led - led.mean(), sphere - sphere.mean(), fps)
    assert estimate.latency_s == pytest.approx(latency, abs=1e-4)
    assert 1 / estimate.frequency_hz == pytest.approx(period, rel=1e-4)


@settings(max_examples=60, deadline=None)
@given(
    lag_fraction=st.floats(-0.45, 0.45),
    phase=st.floats(0, 2 * math.pi),
    cycles=st.floats(3.0, 20.0),
    decay=st.floats(0.0, 0.3),
    fps=st.sampled_from([120.0, 240.0]),
)
def test_delay_of_a_damped_sine_is_recovered(lag_fraction, phase, cycles, decay, fps):
    period = 1.0
    t = np.arange(int(cycles * period * fps)) / fps
    latency = lag_fraction * period
    led = damped_sine(t, period, phase, decay, t.size / fps)
    sphere = damped_sine(t - latency, period, phase, decay, t.size / fps)
    # Damping leaks a little of the 2f image into the phase; it fades as 1/cycles^2.
    assert fft_phase_latency(led, sphere, fps).latency_s == pytest.approx(latency, abs=1e-4)


def test_latency_past_half_a_period_wraps_to_a_lead():
    fps, period = 240.0, 1.0
    t = np.arange(int(10.5 * fps)) / fps
    led = np.sin(2 * math.pi * t / period)
    sphere = np.sin(2 * math.pi * (t - 0.6 * period) / period)
    assert fft_phase_latency(led, sphere, fps).latency_s == pytest.approx(-0.4 * period, abs=1e-9)


def test_fewer_than_two_periods_raise():
    fps = 240.0
    t = np.arange(int(1.6 * fps)) / fps
    with pytest.raises(AnalysisError, match="periods"):
        estimate_frequency(np.sin(2 * math.pi * t), fps)


@given(st.floats(-50.0, 50.0))
def test_wrap_phase_lands_in_half_open_interval(angle):
    wrapped = wrap_phase(angle)
    assert -math.pi < wrapped <= math.pi
    turns = (angle - wrapped) / (2 * math.pi)
    assert turns == pytest.approx(round(turns), abs=1e-9)


def test_wrap_phase_keeps_plus_pi_and_maps_minus_pi_to_it():
    assert wrap_phase(math.pi) == pytest.approx(math.pi)
    assert wrap_phase(-math.pi) == pytest.approx(math.pi)


@given(st.floats(0.0, 2 * math.pi), st.floats(0.05, 3.0))
def test_main_axis_follows_the_motion_with_x_positive(angle, length):
    s = np.linspace(-length, length, 50)
    direction = np.array([math.cos(angle), math.sin(angle)])
    axis = main_axis(10 + s * direction[0], 20 + s * direction[1] + 1e-3 * s**2)
    assert abs(axis @ direction) == pytest.approx(1.0, abs=1e-3)
    if abs(direction[0]) > 0.1:
        assert axis[0] > 0


def test_vertical_main_axis_points_down_the_image():
    s = np.linspace(-5, 5, 40)
    axis = main_axis(np.full_like(s, 3.0), 50 - s)
    assert axis == pytest.approx([0.0, 1.0], abs=1e-12)


def _track(x: np.ndarray, y: np.ndarray, valid: np.ndarray, fps: float = 100.0) -> Track:
    t = np.arange(x.size) / fps
    return Track(
        t, np.where(valid, x, np.nan), np.where(valid, y, np.nan), valid, np.full(x.size, 200.0), np.zeros(x.size, bool)
    )


def test_axis_signal_projects_and_leaves_missing_frames_empty():
    n = 400
    t = np.arange(n) / 100.0
    along = 30 * np.sin(2 * math.pi * t)
    valid = np.ones(n, dtype=bool)
    valid[101:104] = False
    # Motion along (-0.6, 0.8): the rule turns the axis to (0.6, -0.8), so the signal is -along.
    signal = axis_signal(_track(50 - 0.6 * along, 40 + 0.8 * along, valid), "LED")
    expected = -along[valid]
    assert signal[valid] == pytest.approx(expected - expected.mean(), abs=1e-9)
    assert np.isnan(signal[101:104]).all()


def test_uniform_signals_interpolate_gaps_and_resample_uneven_times():
    t = np.array([0.0, 0.01, 0.02, 0.04, 0.05])
    signals = SwingSignals(t, np.array([0.0, 1.0, np.nan, 4.0, 5.0]), np.array([1.0, 1.0, 1.0, 1.0, np.nan]))
    grid, led, sphere = signals.uniform()
    assert grid == pytest.approx(np.arange(6) * 0.01)
    assert led == pytest.approx([0.0, 1.0, 2.0, 3.0, 4.0, 5.0])
    assert sphere == pytest.approx(np.ones(6))


def test_bins_average_each_signal_over_its_own_valid_frames():
    t = np.arange(9) / 10.0
    led = np.arange(9, dtype=float)
    sphere = led.copy()
    sphere[[1, 6, 7, 8]] = np.nan
    bins = binned(SwingSignals(t, led, sphere), 3)
    assert bins.led_t == pytest.approx([0.1, 0.4, 0.7])
    assert bins.led == pytest.approx([1.0, 4.0, 7.0])
    assert bins.sphere_t[:2] == pytest.approx([0.1, 0.4])
    assert bins.sphere[:2] == pytest.approx([1.0, 4.0])
    assert np.isnan(bins.sphere[2]) and bins.sphere_count.tolist() == [2, 3, 0]


def test_blob_that_does_not_move_raises():
    n = 300
    x = 50 + 0.01 * np.sin(np.arange(n) / 10)
    with pytest.raises(AnalysisError, match="does not move"):
        axis_signal(_track(x, np.full(n, 7.0), np.ones(n, dtype=bool)), "LED")


def test_track_found_in_one_frame_raises():
    valid = np.zeros(300, dtype=bool)
    valid[5] = True
    with pytest.raises(AnalysisError, match="fewer than two frames"):
        axis_signal(_track(np.arange(300.0), np.zeros(300), valid), "sphere")
