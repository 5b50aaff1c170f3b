"""Minimise a smooth JAX function: the one module that knows which optimiser library is used.

jaxopt (LBFGS here) is in maintenance mode upstream; swapping it for another library (optax's
L-BFGS, scipy through jax's callbacks) means rewriting `minimise` and nothing else. jaxopt warns
about its status when imported; the import is made here, when a minimisation is asked for, with
that one warning silenced locally, so importing `predictors` changes no warning filter.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any, Callable

import jax
import numpy as np


@dataclass(frozen=True)
class Minimum:
    """Where the minimiser stopped: the point, the value there and the iterations taken."""

    x: np.ndarray
    value: float
    iterations: int


def minimise(
    fun: Callable[[jax.Array], jax.Array], x0: np.ndarray, max_iterations: int = 50, tolerance: float = 1e-6,
    progress: Callable[[int], object] | None = None,
) -> Minimum:
    """Minimise fun (a scalar, differentiable JAX function of a 1-D array) from x0 by L-BFGS-B, in
    float64: call it inside `jax.enable_x64(True)`, as `predictors.tuning.tune` does. `progress` is
    called with the number of iterations done after each one."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="JAXopt is no longer maintained", category=DeprecationWarning)
        import jaxopt

    # scipy's L-BFGS-B drives one compiled value-and-gradient function: a single compilation,
    # where jaxopt's own LBFGS would compile its whole loop and line search around `fun` again.
    iterations = 0

    def count(_: Any) -> None:
        nonlocal iterations
        iterations += 1
        if progress is not None:
            progress(iterations)

    solver = jaxopt.ScipyMinimize(
        fun=jax.jit(jax.value_and_grad(fun)), value_and_grad=True, method="L-BFGS-B", maxiter=max_iterations, tol=tolerance,
        callback=count,
    )
    result = solver.run(jax.numpy.asarray(x0, dtype=jax.numpy.float64))
    return Minimum(np.asarray(result.params), float(result.state.fun_val), int(result.state.iter_num))
