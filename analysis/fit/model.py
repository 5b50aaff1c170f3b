"""The joint model of the LED and sphere swings, in JAX: what `sinefit` fits and `bayes` samples.

The model needs 64-bit floats: phases of a few hundred radians must keep sub-microradian
precision. Importing this module changes no JAX setting; instead each entry point that builds or
fits the model's arrays (``least_squares.fit_sine``, ``SineFit.curves``,
``posterior.sample_posterior``) runs under ``in_float64``, which turns on JAX's 64-bit mode for the
calling thread and the duration of the call only, so a user's own JAX code in the same process
keeps its setting. The analyser imports this module only when a fit is asked for, so
``import analysis`` and the fft and xcorr methods never pay for JAX.

Time tau is measured from the middle of the clip. With D = exp(-gamma tau) the damping envelope
and Phi(tau) = omega tau - zeta h(tau) the swing's phase, the LED's displacement along its axis is

    u(tau) = D [a cos Phi + b sin Phi]                               fundamental
           + D^2 [c2 cos 2Phi + s2 sin 2Phi] + D^3 [c3 cos 3Phi + s3 sin 3Phi]   harmonics
           + o_u + d1_u s + d2_u s^2                                  offset and slow drift

(s = tau over half the clip), and the sphere's is the same swing ``lag`` later, scaled by ``gain``:

    v(tau) = gain D [a cos Phi(tau - lag) + b sin Phi(tau - lag)] + (its own harmonics of
             Phi(tau - lag), offset and drift).

h(tau) = 2 tau^2 phi2(2 gamma tau), phi2(x) = (exp(-x) - 1 + x) / x^2, is the phase of the chirp a
real pendulum makes: its frequency rises as its amplitude decays, d omega / dt = -2 zeta
exp(-2 gamma t) (h -> tau^2 as gamma -> 0). The chirp is what makes the lag measurable beyond one
period: a sphere shown one period later would swing at the LED's frequency of one period earlier.

The model is linear in the 16 coefficients (a, b, harmonics, offsets, drift) and non-linear in
five parameters, held in scaled units so that one unit is a comparable step for each:

    cycles = omega * span / (2 pi)   damping = gamma * span   chirp = zeta * span^2
    phase_lag = lag * omega_ref      gain

(span the clip's length, omega_ref a fixed reference frequency). The linear coefficients are
eliminated by variable projection: for given non-linear parameters they are the weighted
least-squares solution, so the optimiser and the sampler work in five dimensions.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import NamedTuple, TypeVar

import jax
import jax.numpy as jnp

with warnings.catch_warnings():
    # jaxopt announces on import that it is no longer maintained; its LM solver is what we use.
    warnings.filterwarnings("ignore", message="JAXopt is no longer maintained", category=DeprecationWarning)
    import jaxopt

# Non-linear parameters, in order. The linear coefficients are, in order: a, b, the LED's and the
# sphere's offsets, the LED's drift s and s^2, the sphere's, the LED's cos 2Phi, sin 2Phi, cos 3Phi,
# sin 3Phi terms, and the sphere's.
CYCLES, DAMPING, CHIRP, PHASE_LAG, GAIN = range(5)
FUNDAMENTAL = (0, 1, 2, 3)
DRIFT = (4, 5, 6, 7)
HARMONICS = tuple(range(8, 16))
# Below this |x| phi2 is evaluated by its series (the closed form loses digits to cancellation).
_SERIES_BELOW = 1e-2
# Levenberg-Marquardt: iterations and the relative step at which it stops.
MAX_ITERATIONS = 60
STEP_TOLERANCE = 1e-11

_Function = TypeVar("_Function", bound=Callable)


def in_float64(function: _Function) -> _Function:
    """``function``, run with JAX in 64-bit mode (``jax.enable_x64``) in the calling thread for the
    duration of each call; the thread's setting is restored afterwards. The model's arrays made
    inside keep float64 when used later under this mode again."""
    return jax.enable_x64(True)(function)


class FitData(NamedTuple):
    """Samples of both signals, padded to a fixed length N so one compilation serves many videos.

    tau (2N,) s from mid-clip and y (2N,) the LED's samples then the sphere's; w (2N,) their weights
    (1 / noise level; 0 for a missing detection or padding); half_span s; scales (5,) the factors
    turning the scaled non-linear parameters into omega, gamma, zeta, lag and gain.
    """

    tau: jax.Array
    y: jax.Array
    w: jax.Array
    half_span: jax.Array
    scales: jax.Array


class Structure(NamedTuple):
    """Which parameters a model has: free (5,) 1.0 for a fitted non-linear parameter, 0.0 for one
    held at ``fixed``; linear (16,) 1.0 for a coefficient in the model, 0.0 for one left out."""

    free: jax.Array
    fixed: jax.Array
    linear: jax.Array


def _phi2(x: jax.Array) -> jax.Array:
    small = jnp.abs(x) < _SERIES_BELOW
    safe = jnp.where(small, 1.0, x)
    closed = (jnp.expm1(-safe) + safe) / safe**2
    series = 0.5 - x / 6.0 + x**2 / 24.0 - x**3 / 120.0
    return jnp.where(small, series, closed)


def swing_phase(tau: jax.Array, omega: jax.Array, gamma: jax.Array, zeta: jax.Array) -> jax.Array:
    """Phi(tau) = omega tau - zeta h(tau): the phase of a damped pendulum whose frequency drifts."""
    return omega * tau - zeta * 2.0 * tau**2 * _phi2(2.0 * gamma * tau)


def physical(params: jax.Array, structure: Structure, data: FitData) -> jax.Array:
    """(omega, gamma, zeta, lag, gain) from scaled parameters, fixed ones taken from the structure."""
    chosen = structure.free * params + (1.0 - structure.free) * structure.fixed
    return chosen * data.scales


def _placement() -> jax.Array:
    """(2, 9, 16): where each signal's nine basis functions go among the 16 linear coefficients.

    Basis per signal: fundamental cos and sin (shared by both signals through ``gain``), offset,
    drift s and s^2, and the harmonics' cos 2Phi, sin 2Phi, cos 3Phi, sin 3Phi.
    """
    led = [0, 1, 2, 4, 5, 8, 9, 10, 11]
    sphere = [0, 1, 3, 6, 7, 12, 13, 14, 15]
    eye = jnp.eye(16)
    return jnp.stack([eye[jnp.array(led)], eye[jnp.array(sphere)]])


def basis(params: jax.Array, structure: Structure, data: FitData) -> jax.Array:
    """(2, N, 9) each signal's basis functions at its sample times (see ``_placement``); left-out
    functions are zero."""
    omega, gamma, zeta, lag, gain = physical(params, structure, data)
    tau = data.tau.reshape(2, -1)
    lags = jnp.stack([0.0, lag])[:, None]
    gains = jnp.stack([1.0, gain])[:, None]
    envelope = jnp.exp(-gamma * tau)
    phase = swing_phase(tau - lags, omega, gamma, zeta)
    cos, sin = jnp.cos(phase), jnp.sin(phase)
    cos2, sin2 = 2.0 * cos**2 - 1.0, 2.0 * sin * cos
    cos3, sin3 = cos * (4.0 * cos**2 - 3.0), sin * (3.0 - 4.0 * sin**2)
    s = tau / data.half_span
    squared, cubed = envelope**2, envelope**3
    functions = jnp.stack(
        [
            gains * envelope * cos, gains * envelope * sin, jnp.ones_like(s), s, s**2,
            squared * cos2, squared * sin2, cubed * cos3, cubed * sin3,
        ],
        axis=-1,
    )  # fmt: skip
    used = jnp.einsum("kbc,c->kb", _placement(), structure.linear)
    return functions * used[:, None, :]


def design(params: jax.Array, structure: Structure, data: FitData) -> jax.Array:
    """The (2N, 16) matrix of the linear model's columns, unweighted; left-out columns are zero."""
    return jnp.einsum("knb,kbc->knc", basis(params, structure, data), _placement()).reshape(-1, 16)


def _normal_equations(
    params: jax.Array, structure: Structure, data: FitData, weights: jax.Array
) -> tuple[jax.Array, jax.Array, jax.Array, jax.Array]:
    """(weighted basis (2, N, 9), weighted data (2, N), normal matrix (16, 16), right-hand side (16,)).

    Built per signal (9 x 9 blocks placed into 16 x 16): a third of the work of the full design.
    Left-out coefficients get an identity row, so they solve to zero.
    """
    placement = _placement()
    weighted = basis(params, structure, data) * weights.reshape(2, -1, 1)
    target = (weights * data.y).reshape(2, -1)
    blocks = jnp.einsum("knb,knc->kbc", weighted, weighted)
    normal = jnp.einsum("kbi,kbc,kcj->ij", placement, blocks, placement) + jnp.diag(1.0 - structure.linear)
    rhs = jnp.einsum("kbi,knb,kn->i", placement, weighted, target)
    return weighted, target, normal, rhs


def linear_solution(params: jax.Array, structure: Structure, data: FitData) -> tuple[jax.Array, jax.Array]:
    """(coefficients (16,), weighted residual (2N,)) of the weighted least-squares linear fit."""
    weighted, target, normal, rhs = _normal_equations(params, structure, data, data.w)
    coefficients = jnp.linalg.solve(normal, rhs)
    fitted = jnp.einsum("knb,kbi,i->kn", weighted, _placement(), coefficients)
    return coefficients, (target - fitted).reshape(-1)


def projected_residual(params: jax.Array, structure: Structure, data: FitData) -> jax.Array:
    """The weighted residual with the linear coefficients at their best: what LM minimises."""
    return linear_solution(params, structure, data)[1]


_solver = jaxopt.LevenbergMarquardt(
    residual_fun=projected_residual,
    maxiter=MAX_ITERATIONS,
    stop_criterion="madsen-nielsen",
    xtol=STEP_TOLERANCE,
    gtol=0.0,
    solver="cholesky",
    materialize_jac=True,
    implicit_diff=False,
)


@jax.jit
def fit(params: jax.Array, structure: Structure, data: FitData) -> tuple[jax.Array, jax.Array, jax.Array, jax.Array]:
    """Levenberg-Marquardt from ``params``: (scaled parameters, coefficients, residual, iterations)."""
    result = _solver.run(params, structure, data)
    coefficients, residual = linear_solution(result.params, structure, data)
    return result.params, coefficients, residual, result.state.iter_num


def full_residual(combined: jax.Array, structure: Structure, data: FitData) -> jax.Array:
    params, coefficients = combined[:5], combined[5:]
    return data.w * (data.y - design(params, structure, data) @ coefficients)


@jax.jit
def jacobian(
    params: jax.Array, coefficients: jax.Array, structure: Structure, data: FitData
) -> tuple[jax.Array, jax.Array]:
    """((2N, 21) Jacobian of the weighted residual in all parameters, non-linear first; the residual)."""
    combined = jnp.concatenate([params, coefficients])
    return jax.jacfwd(full_residual)(combined, structure, data), full_residual(combined, structure, data)


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
    _, target, normal, rhs = _normal_equations(params, structure, data, weights)
    factor = jnp.linalg.cholesky(normal)
    chi2 = jnp.sum(target**2) - rhs @ jax.scipy.linalg.cho_solve((factor, True), rhs)
    used = jnp.stack([jnp.sum(data.w[:count] > 0), jnp.sum(data.w[count:] > 0)])
    return -jnp.sum(used * log_noise) / inflation - 0.5 * chi2 - jnp.sum(jnp.log(jnp.diag(factor)))
