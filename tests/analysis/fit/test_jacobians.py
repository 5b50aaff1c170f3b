"""The fit's analytic Jacobians against JAX's automatic derivatives of the same residuals."""

from __future__ import annotations

import numpy as np
import pytest

from analysis.fit import model
from analysis.fit.jacobians import full_jacobian, projected_residual_and_jacobian
from analysis.fit.least_squares import RICHEST, make_problem, scaled_guess, structure_of
from analysis.signals import SwingSignals

# Rounding and where the series of phi2' is cut leave differences below 1e-13 of a column's scale;
# a missing or wrong term of the derivative leaves differences of order one.
AGREEMENT = 1e-10


def jax_jacobians(
    params: np.ndarray, coefficients: np.ndarray, structure: model.Structure, data: model.FitData
) -> tuple[np.ndarray, np.ndarray]:
    """JAX's forward-mode Jacobians of the projected and of the full residual (64-bit)."""
    import jax
    import jax.numpy as jnp

    with jax.enable_x64(True):
        structure = model.Structure(*(jnp.asarray(a) for a in structure))
        data = model.FitData(*(jnp.asarray(a) for a in data))
        projected = jax.jacfwd(model.projected_residual)(jnp.asarray(params), structure, data)
        full = jax.jacfwd(model.full_residual)(jnp.asarray(np.concatenate([params, coefficients])), structure, data)
        return np.asarray(projected), np.asarray(full)


def worst_column_error(mine: np.ndarray, reference: np.ndarray) -> float:
    """The largest difference in each column, relative to that column's largest element."""
    scale = np.max(np.abs(reference), axis=0)
    used = scale > 0
    assert np.all(np.abs(mine[:, ~used]) == 0)
    return float(np.max(np.abs(mine - reference)[:, used] / scale[used]))


def assert_jacobians_agree(signals: SwingSignals, guess, name: str) -> model.FitProblem:
    problem = make_problem(signals, (0.3, 0.5), guess)
    params = scaled_guess(guess, problem)
    structure = structure_of(name, params)
    coefficients, residual = model.linear_solution(params, structure, problem.data)
    projected, full = jax_jacobians(params, coefficients, structure, problem.data)
    mine_residual, mine_projected = projected_residual_and_jacobian(params, structure, problem.data)
    np.testing.assert_allclose(mine_residual, residual, rtol=0, atol=1e-12 * np.max(np.abs(residual)))
    assert worst_column_error(mine_projected, projected) < AGREEMENT
    assert worst_column_error(full_jacobian(params, coefficients, structure, problem.data), full) < AGREEMENT
    return problem


def test_jacobians_of_a_damped_chirping_swing_away_from_the_optimum(swing):
    # The guess is off the truth, so the residual, and the projection's term in it, are not zero.
    signals, guess = swing(0.137, decay=0.15, chirp=0.01, wide=0.03, noise=(0.3, 0.5))
    assert_jacobians_agree(signals, guess, RICHEST)


def test_jacobians_of_the_sine_model_whose_damping_is_held_at_zero(swing):
    # gamma = 0: phi2 and its derivative are their series at x = 0 everywhere.
    signals, guess = swing(0.05, noise=(0.3, 0.5))
    assert_jacobians_agree(signals, guess, "sine")


def test_jacobians_at_near_zero_damping_on_phi2s_series_branch(swing):
    signals, guess = swing(0.05, decay=1e-4, chirp=0.01, noise=(0.3, 0.5))
    problem = assert_jacobians_agree(signals, guess, RICHEST)
    assert np.max(np.abs(2 * 1e-4 * problem.data.tau)) < model._SERIES_BELOW


def test_jacobians_with_damping_across_phi2s_switch_to_its_series(swing):
    # 2 gamma tau runs over +-0.02: the samples near mid-clip take the series, the rest the closed form.
    signals, guess = swing(0.05, decay=0.02 / 6.0, chirp=0.01, noise=(0.3, 0.5))
    problem = assert_jacobians_agree(signals, guess, RICHEST)
    x = 2 * 0.02 / 6.0 * problem.data.tau[problem.data.w > 0]
    assert np.any(np.abs(x) < model._SERIES_BELOW) and np.any(np.abs(x) > model._SERIES_BELOW)


@pytest.mark.parametrize("name", ["sine+drift", "damped", "damped+harmonics"])
def test_jacobians_of_models_that_leave_coefficients_out(swing, name):
    signals, guess = swing(0.08, decay=0.1, chirp=0.005, noise=(0.3, 0.5))
    assert_jacobians_agree(signals, guess, name)


def test_jacobians_with_missing_samples(swing):
    signals, guess = swing(0.08, decay=0.1, noise=(0.3, 0.5), seed=4)
    sphere = signals.sphere.copy()
    sphere[200:260] = np.nan
    assert_jacobians_agree(SwingSignals(signals.t, signals.led, sphere), guess, RICHEST)
