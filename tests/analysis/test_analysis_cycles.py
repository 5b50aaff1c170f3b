"""Per-swing windows and the whole number of periods in the latency."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from analysis.cycles import candidate_latencies, chirp_shape, resolve_cycles, unwrap_near
from analysis.signals import SwingSignals
from analysis.windows import WindowPhases, damping_rate, gain_ratio, window_phases, windowed_latency


def phases(latency: float, zeta: float, gamma: float = 0.2, count: int = 12, period: float = 0.6, noise: float = 1e-4):
    """Window phases of a chirping swing and of its copy ``latency`` later (analysis.cycles' model)."""
    rng = np.random.default_rng(3)
    t = (np.arange(count) + 0.5) * period
    centred = t - t.mean()
    omega = 2 * math.pi / period
    led = 0.3 + 0.01 * centred - zeta * chirp_shape(centred, gamma) + noise * rng.standard_normal(count)
    sphere = 0.3 - omega * latency + 0.01 * centred - zeta * chirp_shape(centred - latency, gamma)
    sphere = sphere + noise * rng.standard_normal(count)
    amplitude = 50 * np.exp(-gamma * t)
    return WindowPhases(t, led, sphere, amplitude, 0.7 * amplitude, omega, 0.1, 0.2)


def test_candidates_are_the_whole_period_shifts_inside_the_range():
    assert candidate_latencies(-0.2, 0.6, (-0.2, 0.6)) == pytest.approx([-0.2, 0.4])
    assert candidate_latencies(0.05, 1.0, (-0.2, 0.6)) == pytest.approx([0.05])
    assert candidate_latencies(0.05, 0.1, (0.31, 0.32)) == pytest.approx([0.35])


@given(st.floats(-5, 5), st.floats(-2, 2), st.floats(0.1, 3))
def test_unwrap_near_moves_by_whole_periods_to_within_half_a_period(latency, reference, period):
    moved = unwrap_near(latency, reference, period)
    assert abs(moved - reference) <= period / 2 + 1e-9
    turns = (moved - latency) / period
    assert turns == pytest.approx(round(turns), abs=1e-6)


def test_chirp_shape_is_t_squared_without_damping_and_smooth_through_it():
    t = np.linspace(-3, 3, 7)
    assert chirp_shape(t, 0.0) == pytest.approx(t**2)
    assert chirp_shape(t, 1e-5) == pytest.approx(chirp_shape(t, 2e-5), rel=1e-4)
    gamma = 0.3
    assert chirp_shape(t, gamma) == pytest.approx((np.exp(-2 * gamma * t) - 1 + 2 * gamma * t) / (2 * gamma**2))


def test_one_candidate_in_range_decides_without_evidence():
    resolution = resolve_cycles(0.05, 1.0, phases(0.05, 0.0), 0.2)
    assert (resolution.reference_s, resolution.how, resolution.ambiguous) == (0.05, "range", False)


def test_chirp_tells_a_latency_beyond_half_a_period_from_its_alias():
    resolution = resolve_cycles(-0.2, 0.6, phases(0.4, 0.02), 0.2)
    assert resolution.how == "chirp" and not resolution.ambiguous
    assert resolution.reference_s == pytest.approx(0.4)
    assert resolution.evidence_chi2 > 25 and resolution.separation_s > 0.002


def test_chirp_picks_the_short_candidate_when_that_is_the_truth():
    resolution = resolve_cycles(-0.2, 0.6, phases(-0.2, 0.02), 0.2)
    assert (resolution.how, resolution.reference_s) == ("chirp", pytest.approx(-0.2))


def test_without_a_chirp_the_alternatives_stay_ambiguous():
    resolution = resolve_cycles(-0.2, 0.6, phases(0.4, 0.0), 0.2)
    assert resolution.ambiguous and resolution.how == "unresolved"
    assert resolution.candidates_s == pytest.approx([-0.2, 0.4])
    assert "-200.0, 400.0 ms" in resolution.warning


def test_a_chirp_too_weak_to_outweigh_a_latency_drift_is_ambiguous():
    # Noise-free phases would make any chirp "significant"; the separation rule still refuses it.
    resolution = resolve_cycles(-0.2, 0.6, phases(0.4, 5e-4, noise=1e-7), 0.2)
    assert resolution.ambiguous
    assert resolution.separation_s < 0.002


def sine_signals(latency: float, decay_rate: float = 0.0, fps: float = 120.0, seconds: float = 6.0, period: float = 0.8):
    t = np.arange(int(seconds * fps)) / fps
    led = 40 * np.exp(-decay_rate * t) * np.sin(2 * math.pi * t / period)
    sphere = 25 * np.exp(-decay_rate * (t - latency)) * np.sin(2 * math.pi * (t - latency) / period)
    return SwingSignals(t, led, sphere)


def test_windows_give_the_latency_per_swing_damping_and_gain():
    windows = window_phases(sine_signals(0.07, decay_rate=0.1), 1 / 0.8)
    assert windows.t.size == 7
    assert damping_rate(windows) == pytest.approx(0.1, rel=0.02)
    assert gain_ratio(windows) == pytest.approx(25 / 40 * math.exp(0.1 * 0.07), rel=0.01)
    windowed = windowed_latency(windows, 0.07)
    assert windowed.latency_s == pytest.approx(np.full(7, 0.07), abs=1e-3)
    assert windowed.sd_s < 1e-3 and windowed.count == 7


def test_windows_show_a_latency_that_changes_over_time():
    signals = sine_signals(0.05)
    t = signals.t
    drifting = 25 * np.sin(2 * math.pi * (t - (0.03 + 0.01 * t)) / 0.8)
    windows = window_phases(SwingSignals(t, signals.led, drifting), 1 / 0.8)
    windowed = windowed_latency(windows, 0.05)
    assert windowed.latency_s == pytest.approx(0.03 + 0.01 * windows.t, abs=2e-3)
    assert windowed.sd_s == pytest.approx(np.std(0.01 * windows.t, ddof=1), rel=0.1)


def test_windows_with_too_few_samples_have_no_phase():
    signals = sine_signals(0.05)
    sphere = signals.sphere.copy()
    sphere[:150] = np.nan
    windows = window_phases(SwingSignals(signals.t, signals.led, sphere), 1 / 0.8)
    assert np.isnan(windows.sphere_phase[0]) and np.isfinite(windows.led_phase[0])
    assert windowed_latency(windows, 0.05).count == windows.t.size - 2


def test_events_that_agree_fix_a_latency_beyond_the_chirps_reach():
    resolution = resolve_cycles(-0.2, 0.6, phases(0.4, 0.0), 0.2, event_lags_s={"swing start": 0.41, "swing stop": 0.38})
    assert (resolution.how, resolution.ambiguous) == ("swing start+swing stop", False)
    assert resolution.reference_s == pytest.approx(0.4)


def test_events_that_disagree_decide_nothing_and_say_so():
    resolution = resolve_cycles(-0.2, 0.6, phases(0.4, 0.0), 0.2, event_lags_s={"swing start": 0.41, "swing stop": -0.19})
    assert resolution.ambiguous and resolution.how == "unresolved"
    assert "do not agree" in resolution.warning


def test_an_event_a_quarter_period_off_the_phase_decides_nothing():
    resolution = resolve_cycles(0.05, 1.0, phases(0.05, 0.0), 0.2, event_lags_s={"swing start": 0.40})
    assert resolution.how == "range" and "do not agree" in resolution.warning


def test_an_event_outside_the_plausible_range_is_reported_with_a_warning():
    resolution = resolve_cycles(0.05, 1.0, phases(0.05, 0.0), 0.2, (-0.2, 0.6), {"swing start": 1.04})
    assert resolution.reference_s == pytest.approx(1.05) and not resolution.ambiguous
    assert "outside the range" in resolution.warning
