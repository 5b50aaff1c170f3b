"""The numpy Levenberg-Marquardt: a known minimum, and step for step what jaxopt's does."""

from __future__ import annotations

import numpy as np
import pytest

from analysis.fit import model
from analysis.fit.jacobians import projected_residual_and_jacobian
from analysis.fit.least_squares import RICHEST, STEP_TOLERANCE, make_problem, scaled_guess, structure_of
from analysis.fit.levenberg_marquardt import levenberg_marquardt


def test_an_exponential_decay_is_fitted_to_its_exact_parameters():
    t = np.linspace(0.0, 4.0, 50)
    y = 3.0 * np.exp(-0.7 * t)

    def residual(x: np.ndarray) -> np.ndarray:
        return x[0] * np.exp(-x[1] * t) - y

    def residual_and_jacobian(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        decay = np.exp(-x[1] * t)
        return residual(x), np.stack([decay, -x[0] * t * decay], axis=1)

    solution = levenberg_marquardt(residual, residual_and_jacobian, np.array([1.0, 2.0]), 60, STEP_TOLERANCE)
    np.testing.assert_allclose(solution.params, [3.0, 0.7], rtol=1e-12)
    assert solution.iterations < 60


def test_the_iterations_end_at_the_limit():
    t = np.linspace(0.0, 4.0, 50)
    y = 3.0 * np.exp(-0.7 * t)

    def residual_and_jacobian(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        decay = np.exp(-x[1] * t)
        return x[0] * decay - y, np.stack([decay, -x[0] * t * decay], axis=1)

    solution = levenberg_marquardt(lambda x: residual_and_jacobian(x)[0], residual_and_jacobian, np.array([1.0, 2.0]), 2, 0.0)
    assert solution.iterations == 2


@pytest.mark.parametrize("iterations", [1, 2, 5])
def test_each_step_is_the_step_jaxopts_levenberg_marquardt_takes(swing, jaxopt_solver, iterations):
    """The numpy solver replaced jaxopt's (madsen-nielsen, Cholesky, materialised Jacobian) in the
    fit; while the steps are well above rounding, the two take the same ones."""
    import jax
    import jax.numpy as jnp

    signals, guess = swing(0.137, decay=0.15, chirp=0.01, wide=0.03, noise=(0.3, 0.5))
    problem = make_problem(signals, (0.3, 0.5), guess)
    start = scaled_guess(guess, problem)
    structure = structure_of(RICHEST, start)
    solver = jaxopt_solver(iterations)
    with jax.enable_x64(True):
        as_jax = [type(pack)(*(jnp.asarray(a) for a in pack)) for pack in (structure, problem.data)]
        reference = solver.run(jnp.asarray(start), *as_jax)
        reference_params = np.asarray(reference.params)
    solution = levenberg_marquardt(
        lambda x: model.projected_residual(x, structure, problem.data),
        lambda x: projected_residual_and_jacobian(x, structure, problem.data),
        start,
        iterations,
        STEP_TOLERANCE,
    )
    assert solution.iterations == int(reference.state.iter_num) == iterations
    np.testing.assert_allclose(solution.params, reference_params, rtol=0, atol=1e-12 * np.max(np.abs(reference_params)))
