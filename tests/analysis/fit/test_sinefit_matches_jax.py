"""The numpy fit against the JAX fit it replaced, on the hard cases: the same model chosen, the
latency within a thousandth of its standard error, the standard error within a thousandth.

The JAX fit is rebuilt here from the same model functions (``analysis.fit.model`` works on JAX
arrays too): jaxopt's Levenberg-Marquardt on the projected residual, and JAX's forward-mode
Jacobian for the covariance, as the fit was before it moved to numpy.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from analysis.fit import least_squares, model
from analysis.fit.least_squares import MAX_ITERATIONS, SineFit, fit_sine
from analysis.signals import SwingSignals

# A clip of under five periods: its errors in units of the standard error are heavy-tailed (the
# interval uses a fixed-b critical value near 3, see test_short_clip_coverage.py), so the truth is
# checked to a fixed bound, a thirtieth of the 60 fps frame interval.
SHORT_CLIP_ACCURACY = 5e-4


@functools.cache
def compiled(solver: Any) -> Callable:
    """The solver's run, compiled once for every test here."""
    import jax

    return jax.jit(solver.run)


def jax_fit(solver: Any, params: np.ndarray, structure: model.Structure, data: model.FitData) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    import jax
    import jax.numpy as jnp

    with jax.enable_x64(True):
        as_jax = [type(pack)(*(jnp.asarray(a) for a in pack)) for pack in (structure, data)]
        result = compiled(solver)(jnp.asarray(params), *as_jax)
        fitted = np.asarray(result.params)
    coefficients, residual = model.linear_solution(fitted, structure, data)
    return fitted, coefficients, residual, int(result.state.iter_num)


def jax_full_jacobian(params: np.ndarray, coefficients: np.ndarray, structure: model.Structure, data: model.FitData) -> np.ndarray:
    import jax
    import jax.numpy as jnp

    with jax.enable_x64(True):
        as_jax = [type(pack)(*(jnp.asarray(a) for a in pack)) for pack in (structure, data)]
        return np.asarray(jax.jacfwd(model.full_residual)(jnp.asarray(np.concatenate([params, coefficients])), *as_jax))


def assert_matches_the_jax_fit(signals: SwingSignals, noise: tuple[float, float], guess, monkeypatch, jaxopt_solver) -> SineFit:
    fit = fit_sine(signals, noise, guess)
    with monkeypatch.context() as patched:
        patched.setattr(least_squares, "_fit", functools.partial(jax_fit, jaxopt_solver(MAX_ITERATIONS)))
        patched.setattr(least_squares, "full_jacobian", jax_full_jacobian)
        reference = fit_sine(signals, noise, guess)
    assert fit.model == reference.model
    assert fit.latency_s == pytest.approx(reference.latency_s, abs=max(1e-3 * reference.se_s, 1e-6))
    assert fit.se_s == pytest.approx(reference.se_s, rel=1e-3)
    assert fit.naive_se_s == pytest.approx(reference.naive_se_s, rel=1e-3)
    assert fit.frequency_hz == pytest.approx(reference.frequency_hz, rel=1e-9)
    return fit


def test_near_zero_damping_on_phi2s_series_branch(swing, monkeypatch, jaxopt_solver):
    signals, guess = swing(0.06, decay=2e-4, chirp=0.01, noise=(0.05, 0.1))
    fit = assert_matches_the_jax_fit(signals, (0.05, 0.1), guess, monkeypatch, jaxopt_solver)
    assert fit.model.startswith("damped")
    assert np.max(np.abs(2 * fit.damping * fit.problem.data.tau)) < model._SERIES_BELOW
    assert fit.latency_s == pytest.approx(0.06, abs=4 * fit.se_s)


def test_a_pure_sine(swing, monkeypatch, jaxopt_solver):
    signals, guess = swing(0.05, noise=(0.05, 0.1))
    fit = assert_matches_the_jax_fit(signals, (0.05, 0.1), guess, monkeypatch, jaxopt_solver)
    assert fit.model == "sine"
    assert fit.latency_s == pytest.approx(0.05, abs=4 * fit.se_s)


def test_a_noise_free_pure_sine(swing, monkeypatch, jaxopt_solver):
    signals, guess = swing(0.05)
    fit = assert_matches_the_jax_fit(signals, (0.01, 0.01), guess, monkeypatch, jaxopt_solver)
    assert fit.latency_s == pytest.approx(0.05, abs=1e-7)


def test_a_clip_of_two_and_a_half_periods(swing, monkeypatch, jaxopt_solver):
    signals, guess = swing(0.09, seconds=2.0, fps=60.0, decay=0.2, noise=(0.1, 0.2), seed=3)
    fit = assert_matches_the_jax_fit(signals, (0.1, 0.2), guess, monkeypatch, jaxopt_solver)
    assert fit.latency_s == pytest.approx(0.09, abs=SHORT_CLIP_ACCURACY)


def test_a_short_clip_binned_at_one_frame_a_bin(swing, monkeypatch, jaxopt_solver):
    signals, guess = swing(0.03, period=0.25, seconds=1.2, fps=60.0, decay=0.3, noise=(0.1, 0.2), seed=5)
    fit = assert_matches_the_jax_fit(signals, (0.1, 0.2), guess, monkeypatch, jaxopt_solver)
    assert fit.problem.bins.frames_per_bin == 1
    assert fit.latency_s == pytest.approx(0.03, abs=SHORT_CLIP_ACCURACY)


def test_strong_damping_with_harmonics_and_drift(swing, monkeypatch, jaxopt_solver):
    signals, guess = swing(0.12, decay=0.4, chirp=0.05, wide=0.05, drift=2.0, noise=(0.05, 0.1), seed=7)
    fit = assert_matches_the_jax_fit(signals, (0.05, 0.1), guess, monkeypatch, jaxopt_solver)
    assert fit.model == "damped+harmonics+drift"
    assert fit.latency_s == pytest.approx(0.12, abs=4 * fit.se_s)


def test_a_latency_of_more_than_half_a_period(swing, monkeypatch, jaxopt_solver):
    signals, guess = swing(0.55, decay=0.15, chirp=0.03, noise=(0.05, 0.1), seed=9)
    fit = assert_matches_the_jax_fit(signals, (0.05, 0.1), guess, monkeypatch, jaxopt_solver)
    assert fit.latency_s == pytest.approx(0.55, abs=4 * fit.se_s)
