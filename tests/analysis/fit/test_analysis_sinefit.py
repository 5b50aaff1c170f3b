"""The joint fit on swing signals of known latency: accuracy, model choice, honest uncertainty."""

import numpy as np
import pytest

from analysis.signals import SwingSignals
from analysis.fit.least_squares import Guess, fit_sine, frames_per_bin, long_run_variance

PERIOD = 0.8


@pytest.fixture
def swing_signals(swing):
    """The conftest's swing signals alone (its default swing: a 0.8 s period, 6 s at 120 fps)."""
    return lambda latency, **options: swing(latency, **options)[0]


def guess(latency: float) -> Guess:
    return Guess(1 / PERIOD * 1.0005, 0.0, 0.0, latency + 0.004, 0.6)


def test_noise_free_damped_chirping_swing_is_fitted_exactly(swing_signals):
    fit = fit_sine(swing_signals(0.137, decay=0.15, chirp=0.01), (0.01, 0.01), guess(0.137))
    assert fit.latency_s == pytest.approx(0.137, abs=2e-6)
    assert fit.frequency_hz == pytest.approx(1 / PERIOD, rel=1e-4)
    assert fit.damping == pytest.approx(0.15, rel=1e-3)
    assert fit.model.startswith("damped")


@pytest.mark.parametrize(
    ("kind", "model"),
    [({}, "sine"), ({"decay": 0.2}, "damped"), ({"decay": 0.2, "wide": 0.03}, "damped+harmonics")],
    ids=["pure", "damped", "wide"],
)
def test_the_simplest_model_the_data_support_is_chosen(kind, model, swing_signals):
    fit = fit_sine(swing_signals(0.05, noise=(0.05, 0.1), **kind), (0.05, 0.1), guess(0.05))
    assert fit.model == model
    assert fit.latency_s == pytest.approx(0.05, abs=5 * fit.se_s)


def test_missing_samples_carry_no_weight(swing_signals):
    signals = swing_signals(0.08, decay=0.1, noise=(0.05, 0.1), seed=4)
    sphere = signals.sphere.copy()
    sphere[np.random.default_rng(1).choice(sphere.size, sphere.size // 10, replace=False)] = np.nan
    sphere[200:260] = np.nan
    fit = fit_sine(SwingSignals(signals.t, signals.led, sphere), (0.05, 0.1), guess(0.08))
    assert fit.latency_s == pytest.approx(0.08, abs=4 * fit.se_s)
    assert fit.se_s < 2e-4


def test_standard_errors_match_the_scatter_over_noise_draws(swing_signals):
    errors, ses = [], []
    for seed in range(24):
        fit = fit_sine(swing_signals(0.06, decay=0.1, noise=(0.3, 0.5), seed=seed), (0.3, 0.5), guess(0.06))
        errors.append(fit.latency_s - 0.06)
        ses.append(fit.se_s)
    z = np.array(errors) / np.array(ses)
    assert 0.6 < np.std(z) < 1.4
    assert np.mean(np.abs(z) < 1.96) >= 0.8


def test_correlated_residuals_widen_the_interval(swing_signals):
    rng = np.random.default_rng(2)
    signals = swing_signals(0.06, decay=0.1)
    # A slow random wander (AR(1), 0.97 per frame) on the sphere: far fewer independent samples.
    wander = np.zeros(signals.t.size)
    for i in range(1, wander.size):
        wander[i] = 0.97 * wander[i - 1] + 0.2 * rng.standard_normal()
    fit = fit_sine(SwingSignals(signals.t, signals.led, signals.sphere + wander), (0.05, 0.8), guess(0.06))
    assert fit.inflation > 2
    assert fit.se_s > 1.5 * fit.naive_se_s
    assert fit.ci95_s[0] <= 0.06 <= fit.ci95_s[1]


def test_long_run_variance_of_white_and_correlated_series():
    rng = np.random.default_rng(5)
    white = rng.standard_normal(20000)
    assert long_run_variance(white, 20) == pytest.approx(20000, rel=0.1)
    correlated = np.convolve(white, np.ones(5), mode="same")
    # Sum of 5 neighbours: long-run variance 25 per sample.
    assert long_run_variance(correlated, 40) == pytest.approx(25 * 20000, rel=0.15)


def test_frames_are_binned_to_about_sixteen_per_period():
    assert frames_per_bin(1 / 240, 1.0) == 15
    assert frames_per_bin(1 / 60, 0.6) == 2
    assert frames_per_bin(1 / 60, 0.3) == 1


def test_posterior_agrees_with_the_fit_and_reports_its_sampler(swing_signals):
    from analysis.fit.posterior import sample_posterior

    fit = fit_sine(swing_signals(0.06, decay=0.1, noise=(0.3, 0.5), seed=3), (0.3, 0.5), guess(0.06))
    posterior = sample_posterior(fit, seed=1, steps=300, burn_in=100)
    assert posterior.median_s == pytest.approx(fit.latency_s, abs=0.3 * fit.se_s)
    width = posterior.ci95_s[1] - posterior.ci95_s[0]
    assert width == pytest.approx(fit.ci95_s[1] - fit.ci95_s[0], rel=0.3)
    assert posterior.ci95_s[0] <= 0.06 <= posterior.ci95_s[1]
    details = posterior.details()
    assert 0.1 < details["acceptance_fraction"] < 0.9
    assert 1 < details["autocorrelation_steps"] < posterior.steps / 5
    assert sample_posterior(fit, seed=1, steps=300, burn_in=100).median_s == posterior.median_s


def test_an_interrupt_in_the_likelihood_ends_the_sampling_without_emcees_traceback(monkeypatch, capsys, swing_signals):
    from analysis.fit import posterior

    fit = fit_sine(swing_signals(0.06, decay=0.1, noise=(0.3, 0.5), seed=3), (0.3, 0.5), guess(0.06))
    calls = []
    likelihood = posterior._log_posterior

    def interrupted_on_the_fifth_call(*arguments):
        calls.append(1)
        if len(calls) == 5:
            raise KeyboardInterrupt
        return likelihood(*arguments)

    monkeypatch.setattr(posterior, "_log_posterior", interrupted_on_the_fifth_call)
    with pytest.raises(KeyboardInterrupt):
        posterior.sample_posterior(fit, seed=1, steps=300, burn_in=100)
    assert len(calls) == 5
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err and "emcee" not in captured.out


def test_the_fit_is_64_bit_in_a_process_whose_jax_is_32_bit(swing_signals):
    import jax

    with jax.enable_x64(False):
        fit = fit_sine(swing_signals(0.137, decay=0.15, chirp=0.01), (0.01, 0.01), guess(0.137))
        curves = fit.curves()
        assert not jax.config.jax_enable_x64
    assert fit.problem.data.tau.dtype == fit.problem.data.y.dtype == np.float64
    assert fit.params.dtype == fit.covariance.dtype == np.float64
    assert all(values.dtype == np.float64 for curve in curves for values in curve)
    assert fit.latency_s == pytest.approx(0.137, abs=2e-6)
