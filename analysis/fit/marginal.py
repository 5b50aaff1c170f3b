"""The model's marginal likelihood in JAX, for the posterior (``posterior``, the bayes method).

This is the one part of ``analysis.fit`` that imports JAX. Importing it changes no JAX setting:
the likelihood needs 64-bit floats, and the sampler asks for them per call (``in_float64``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

import jax
import jax.numpy as jnp

from analysis.fit.model import FitData, Structure, basis, normal_equations

_Function = TypeVar("_Function", bound=Callable)


def in_float64(function: _Function) -> _Function:
    """``function``, run with JAX in 64-bit mode (``jax.enable_x64``) in the calling thread for the
    duration of each call; the thread's setting is restored afterwards. The model's arrays made
    inside keep float64 when used later under this mode again."""
    return jax.enable_x64(True)(function)


def log_marginal(
    params: jax.Array, log_noise: jax.Array, inflation: jax.Array, structure: Structure, data: FitData
) -> jax.Array:
    """Log likelihood, the linear coefficients integrated out under flat priors.

    Each signal's weighted residuals are Gaussian with standard deviation exp(log_noise[k]); the
    log likelihood is divided by ``inflation`` (an effective-sample-size correction: correlated
    residuals carry less information than as many independent ones).
    """
    count = data.tau.shape[0] // 2
    weights = data.w / jnp.repeat(jnp.exp(log_noise) * jnp.sqrt(inflation), count)
    _, target, normal, rhs = normal_equations(basis(params, structure, data), structure, data, weights)
    factor = jnp.linalg.cholesky(normal)
    chi2 = jnp.sum(target**2) - rhs @ jax.scipy.linalg.cho_solve((factor, True), rhs)
    used = jnp.stack([jnp.sum(data.w[:count] > 0), jnp.sum(data.w[count:] > 0)])
    return -jnp.sum(used * log_noise) / inflation - 0.5 * chi2 - jnp.sum(jnp.log(jnp.diag(factor)))
