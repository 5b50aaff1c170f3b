"""The joint model of the LED and sphere swings: what `sinefit` fits and `bayes` samples.

One definition serves both: each function computes with the namespace of its arrays
(``array_namespace``), numpy for the least-squares fit (``least_squares``, which therefore never
imports JAX) and jax.numpy for the posterior, whose likelihood (``marginal``) JAX traces and
differentiates through these same functions. The model needs 64-bit floats: phases of a few
hundred radians must keep sub-microradian precision; numpy's are, and the posterior asks JAX for
them per call (``marginal.in_float64``).

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

import sys
from types import ModuleType
from typing import Any, NamedTuple

import numpy as np

# Non-linear parameters, in order. The linear coefficients are, in order: a, b, the LED's and the
# sphere's offsets, the LED's drift s and s^2, the sphere's, the LED's cos 2Phi, sin 2Phi, cos 3Phi,
# sin 3Phi terms, and the sphere's.
CYCLES, DAMPING, CHIRP, PHASE_LAG, GAIN = range(5)
FUNDAMENTAL = (0, 1, 2, 3)
DRIFT = (4, 5, 6, 7)
HARMONICS = tuple(range(8, 16))
# Below this |x| phi2 and its derivative are evaluated by their series (the closed forms lose
# digits to cancellation).
_SERIES_BELOW = 1e-2

Array = Any  # a numpy array, or a JAX array (or tracer) when the posterior traces the model


def array_namespace(*arrays: object) -> ModuleType:
    """jax.numpy if any of ``arrays`` is a JAX array (a tracer included), else numpy. A JAX array
    exists only once JAX is imported, so asking never imports it."""
    jax = sys.modules.get("jax")
    if jax is not None and any(isinstance(array, jax.Array) for array in arrays):
        return sys.modules["jax.numpy"]
    return np


class FitData(NamedTuple):
    """Samples of both signals, padded to a fixed length N so one compilation serves many videos.

    tau (2N,) s from mid-clip and y (2N,) the LED's samples then the sphere's; w (2N,) their weights
    (1 / noise level; 0 for a missing detection or padding); half_span s; scales (5,) the factors
    turning the scaled non-linear parameters into omega, gamma, zeta, lag and gain.
    """

    tau: Array
    y: Array
    w: Array
    half_span: Array
    scales: Array


class Structure(NamedTuple):
    """Which parameters a model has: free (5,) 1.0 for a fitted non-linear parameter, 0.0 for one
    held at ``fixed``; linear (16,) 1.0 for a coefficient in the model, 0.0 for one left out."""

    free: Array
    fixed: Array
    linear: Array


def _namespace(params: Array, structure: Structure, data: FitData) -> ModuleType:
    return array_namespace(params, *structure, *data)


def _phi2(x: Array, xp: ModuleType) -> Array:
    small = xp.abs(x) < _SERIES_BELOW
    safe = xp.where(small, 1.0, x)
    closed = (xp.expm1(-safe) + safe) / safe**2
    series = 0.5 - x / 6.0 + x**2 / 24.0 - x**3 / 120.0
    return xp.where(small, series, closed)


def _phi2_slope(x: Array, phi2: Array, xp: ModuleType) -> Array:
    """phi2'(x) = (phi1(x) - 2 phi2(x)) / x, phi1(x) = (1 - exp(-x)) / x; by its series near 0.

    The closed form's relative error grows as eps / x^2 (about 6e-12 at the switch to the series);
    the series' first omitted term, x^4 / 1008, is 6e-11 of it there (that of phi2's, x^4 / 720,
    3e-11 of phi2).
    """
    small = xp.abs(x) < _SERIES_BELOW
    safe = xp.where(small, 1.0, x)
    closed = (-xp.expm1(-safe) / safe - 2.0 * phi2) / safe
    series = -1.0 / 6.0 + x / 12.0 - x**2 / 40.0 + x**3 / 180.0
    return xp.where(small, series, closed)


def swing_phase(tau: Array, omega: Array, gamma: Array, zeta: Array) -> Array:
    """Phi(tau) = omega tau - zeta h(tau): the phase of a damped pendulum whose frequency drifts."""
    xp = array_namespace(tau, omega, gamma, zeta)
    return omega * tau - zeta * 2.0 * tau**2 * _phi2(2.0 * gamma * tau, xp)


def physical(params: Array, structure: Structure, data: FitData) -> Array:
    """(omega, gamma, zeta, lag, gain) from scaled parameters, fixed ones taken from the structure."""
    chosen = structure.free * params + (1.0 - structure.free) * structure.fixed
    return chosen * data.scales


def _placement() -> np.ndarray:
    """(2, 9, 16): where each signal's nine basis functions go among the 16 linear coefficients.

    Basis per signal: fundamental cos and sin (shared by both signals through ``gain``), offset,
    drift s and s^2, and the harmonics' cos 2Phi, sin 2Phi, cos 3Phi, sin 3Phi.
    """
    led = [0, 1, 2, 4, 5, 8, 9, 10, 11]
    sphere = [0, 1, 3, 6, 7, 12, 13, 14, 15]
    eye = np.eye(16)
    return np.stack([eye[led], eye[sphere]])


PLACEMENT = _placement()


class _Swing(NamedTuple):
    """What the basis and its derivatives share: (omega, gamma, zeta, lag, gain), and per signal
    (2, N) the times from mid-clip, the times less the signal's lag, its gain, the envelope D, and
    the cos and sin of Phi, 2 Phi and 3 Phi."""

    physical: Array
    tau: Array
    shifted: Array
    gains: Array
    envelope: Array
    harmonics: tuple[Array, Array, Array, Array, Array, Array]


def _swing(params: Array, structure: Structure, data: FitData, xp: ModuleType) -> _Swing:
    values = physical(params, structure, data)
    omega, gamma, zeta, lag, gain = values
    tau = data.tau.reshape(2, -1)
    shifted = tau - xp.stack([0.0, lag])[:, None]
    phase = swing_phase(shifted, omega, gamma, zeta)
    cos, sin = xp.cos(phase), xp.sin(phase)
    cos2, sin2 = 2.0 * cos**2 - 1.0, 2.0 * sin * cos
    cos3, sin3 = cos * (4.0 * cos**2 - 3.0), sin * (3.0 - 4.0 * sin**2)
    gains = xp.stack([1.0, gain])[:, None]
    return _Swing(values, tau, shifted, gains, xp.exp(-gamma * tau), (cos, sin, cos2, sin2, cos3, sin3))


def _used(structure: Structure, xp: ModuleType) -> Array:
    """(2, 9): 1.0 where a signal's basis function is in the model."""
    return xp.einsum("kbc,c->kb", PLACEMENT, structure.linear)


def basis(params: Array, structure: Structure, data: FitData) -> Array:
    """(2, N, 9) each signal's basis functions at its sample times (see ``_placement``); left-out
    functions are zero."""
    xp = _namespace(params, structure, data)
    swing = _swing(params, structure, data, xp)
    cos, sin, cos2, sin2, cos3, sin3 = swing.harmonics
    envelope = swing.envelope
    s = swing.tau / data.half_span
    squared, cubed = envelope**2, envelope**3
    functions = xp.stack(
        [
            swing.gains * envelope * cos, swing.gains * envelope * sin, xp.ones_like(s), s, s**2,
            squared * cos2, squared * sin2, cubed * cos3, cubed * sin3,
        ],
        axis=-1,
    )  # fmt: skip
    return functions * _used(structure, xp)[:, None, :]


def basis_slopes(params: Array, structure: Structure, data: FitData) -> Array:
    """(5, 2, N, 9): the derivatives of ``basis`` in each scaled non-linear parameter (zero for
    one the structure holds fixed), analytic.

    With Phi_p the derivative of the phase, L_p that of log D and g_p that of the gain, the m-th
    harmonic D^m (cos m Phi, sin m Phi) has derivative m D^m (L_p cos m Phi - Phi_p sin m Phi,
    L_p sin m Phi + Phi_p cos m Phi); the fundamental g D (cos Phi, sin Phi) has g times that, plus
    g_p D (cos Phi, sin Phi). The phase's: Phi_omega = t, Phi_zeta = -h(t), Phi_gamma = -zeta dh/dgamma = -4 zeta t^3 phi2'(2 gamma t),
    Phi_lag = -dPhi/dt = -(omega - zeta dh/dt), dh/dt = 4 t phi2 + 4 gamma t^2 phi2' (the sphere's
    only; t = tau less the signal's lag); L_gamma = -tau.
    """
    xp = _namespace(params, structure, data)
    swing = _swing(params, structure, data, xp)
    omega, gamma, zeta, _, _ = swing.physical
    t = swing.shifted
    x = 2.0 * gamma * t
    phi2 = _phi2(x, xp)
    slope = _phi2_slope(x, phi2, xp)
    zero = xp.zeros_like(t)
    sphere = xp.stack([zero[0], xp.ones_like(t[1])])
    phase_slopes = xp.stack(
        [t, -4.0 * zeta * t**3 * slope, -2.0 * t**2 * phi2, -sphere * (omega - zeta * (4.0 * t * phi2 + 2.0 * t * x * slope)), zero]
    )
    envelope_slopes = xp.stack([zero, -swing.tau, zero, zero, zero])
    gain_slopes = xp.stack([zero, zero, zero, zero, sphere])
    cos, sin, cos2, sin2, cos3, sin3 = swing.harmonics
    envelope = swing.envelope
    fundamental = swing.gains * envelope
    squared, cubed = envelope**2, envelope**3
    turn, grow = phase_slopes, envelope_slopes
    constant = xp.zeros_like(turn)
    slopes = xp.stack(
        [
            fundamental * (grow * cos - turn * sin) + gain_slopes * envelope * cos,
            fundamental * (grow * sin + turn * cos) + gain_slopes * envelope * sin,
            constant, constant, constant,
            2.0 * squared * (grow * cos2 - turn * sin2), 2.0 * squared * (grow * sin2 + turn * cos2),
            3.0 * cubed * (grow * cos3 - turn * sin3), 3.0 * cubed * (grow * sin3 + turn * cos3),
        ],
        axis=-1,
    )  # fmt: skip
    chain = structure.free * data.scales
    return slopes * _used(structure, xp)[None, :, None, :] * chain[:, None, None, None]


def design(params: Array, structure: Structure, data: FitData) -> Array:
    """The (2N, 16) matrix of the linear model's columns, unweighted; left-out columns are zero."""
    xp = _namespace(params, structure, data)
    return xp.einsum("knb,kbc->knc", basis(params, structure, data), PLACEMENT).reshape(-1, 16)


def normal_equations(
    functions: Array, structure: Structure, data: FitData, weights: Array
) -> tuple[Array, Array, Array, Array]:
    """(weighted basis (2, N, 9), weighted data (2, N), normal matrix (16, 16), right-hand side (16,))
    of the basis ``functions`` (2, N, 9).

    Built per signal (9 x 9 blocks placed into 16 x 16): a third of the work of the full design.
    Left-out coefficients get an identity row, so they solve to zero.
    """
    xp = array_namespace(functions, weights, *structure, *data)
    weighted = functions * weights.reshape(2, -1, 1)
    target = (weights * data.y).reshape(2, -1)
    blocks = xp.einsum("knb,knc->kbc", weighted, weighted)
    normal = xp.einsum("kbi,kbc,kcj->ij", PLACEMENT, blocks, PLACEMENT) + xp.diag(1.0 - structure.linear)
    rhs = xp.einsum("kbi,kb->i", PLACEMENT, xp.einsum("knb,kn->kb", weighted, target))
    return weighted, target, normal, rhs


def linear_solution(params: Array, structure: Structure, data: FitData) -> tuple[Array, Array]:
    """(coefficients (16,), weighted residual (2N,)) of the weighted least-squares linear fit."""
    xp = _namespace(params, structure, data)
    weighted, target, normal, rhs = normal_equations(basis(params, structure, data), structure, data, data.w)
    coefficients = xp.linalg.solve(normal, rhs)
    fitted = xp.einsum("knb,kb->kn", weighted, xp.einsum("kbi,i->kb", PLACEMENT, coefficients))
    return coefficients, (target - fitted).reshape(-1)


def projected_residual(params: Array, structure: Structure, data: FitData) -> Array:
    """The weighted residual with the linear coefficients at their best: what LM minimises."""
    return linear_solution(params, structure, data)[1]


def full_residual(combined: Array, structure: Structure, data: FitData) -> Array:
    """The weighted residual in all 5 + 16 parameters, non-linear first."""
    params, coefficients = combined[:5], combined[5:]
    return data.w * (data.y - design(params, structure, data) @ coefficients)
