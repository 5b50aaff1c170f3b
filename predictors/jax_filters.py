"""The Kalman and DESP predictors as pure JAX functions over `lax.scan`, for batched tuning.

The twins need float64: they must agree with the real-time predictors to 1e-9 and the filters'
variances span many decades. Importing this module changes no JAX setting; make the arrays and run
the twins inside `with jax.enable_x64(True):` (JAX's switch for the current thread, restored on
leaving; `predictors.tuning.tune` does this itself). A twin given float32 times, as arrays made
outside would be, raises PredictorError. Nothing else in `predictors` imports JAX, so the real-time
path never pays for it.

Each function takes parameters (a NamedTuple of scalars, in natural units) and one trace as arrays
in arrival order, and returns the pose predicted at `query_times[k]` after taking sample k, exactly
what `predictors.evaluation.replay` records for the real-time predictor. Everything is jittable,
differentiable in the parameters and vmappable over parameter sets and (equal-length) traces; pad
shorter traces with `valid` False, which makes a step a no-op. `predictions` runs the twin of a
predictor by name, its NamedTuple built from the parameter values by their declared names
(`predictors.registry.params_of`).

They implement the same models and sample rules as the real-time classes (see `predictors.kalman`
and `predictors.desp`), with the covariance in the textbook form P <- F P F^T + Q and
P <- P - K H P instead of the factored form: the two agree to rounding, which the tests check.
"""

from __future__ import annotations

from typing import Any, Mapping, NamedTuple

import jax
import jax.numpy as jnp
from jax import lax

from predictors.desp import INTERVAL_RATE, ORIENTATION_ALPHA, POSITION_ALPHA, SAMPLE_INTERVAL
from predictors.errors import PredictorError
from predictors.jax_quaternion import rotated_by, rotation_vector_between, slerp
from predictors.kalman import (
    ACCELERATION_NOISE,
    ANGULAR_ACCELERATION_NOISE,
    ANGULAR_VELOCITY_DAMPING,
    INITIAL_ACCELERATION_STD,
    INITIAL_ANGULAR_SPEED_STD,
    INITIAL_SPEED_STD,
    JERK_NOISE,
    ORIENTATION_NOISE,
    POSITION_NOISE,
)
from predictors.kinematic_covariance import SERIES_BELOW
from predictors.params import MAX_GAP, MAX_HORIZON

Array = jax.Array

# The predictors that have a twin here, and the Kalman filters' orders.
TWINNED = ("kalman-cv", "kalman-ca", "desp")
_KALMAN_ORDERS = {"kalman-cv": 2, "kalman-ca": 3}


class KalmanParams(NamedTuple):
    """Parameters of `kalman-cv` (order 2) or `kalman-ca` (order 3); see those classes for units.

    position_drive is acceleration_noise (order 2) or jerk_noise (order 3). angular_velocity_damping
    None (the default, so that parameter sets built before it existed still work) is the undamped
    model, as is 0.
    """

    position_noise: Array
    position_drive: Array
    orientation_noise: Array
    angular_acceleration_noise: Array
    max_gap: Array
    max_horizon: Array
    angular_velocity_damping: Array | None = None


class DespParams(NamedTuple):
    """Parameters of `desp`; sample_interval <= 0 means estimate it from the samples."""

    position_alpha: Array
    orientation_alpha: Array
    sample_interval: Array
    max_gap: Array
    max_horizon: Array


def kalman_params(order: int, values: Mapping[str, Any]) -> KalmanParams:
    """The twin's parameters from every parameter of `kalman-cv` (order 2) or `kalman-ca` (order 3)
    by its declared name, as numbers or JAX scalars (traced ones too), in natural units."""
    drive = ACCELERATION_NOISE if order == 2 else JERK_NOISE
    return KalmanParams(
        jnp.asarray(values[POSITION_NOISE.name]),
        jnp.asarray(values[drive.name]),
        jnp.asarray(values[ORIENTATION_NOISE.name]),
        jnp.asarray(values[ANGULAR_ACCELERATION_NOISE.name]),
        jnp.asarray(values[MAX_GAP.name]),
        jnp.asarray(values[MAX_HORIZON.name]),
        jnp.asarray(values[ANGULAR_VELOCITY_DAMPING.name]),
    )


def desp_params(values: Mapping[str, Any]) -> DespParams:
    """The twin's parameters from every parameter of `desp` by its declared name (a sample_interval
    of None, estimate it, becomes 0)."""
    interval = values[SAMPLE_INTERVAL.name]
    return DespParams(
        jnp.asarray(values[POSITION_ALPHA.name]),
        jnp.asarray(values[ORIENTATION_ALPHA.name]),
        jnp.asarray(0.0 if interval is None else interval),
        jnp.asarray(values[MAX_GAP.name]),
        jnp.asarray(values[MAX_HORIZON.name]),
    )


class TraceArrays(NamedTuple):
    """One trace in arrival order: times (N,), positions (N, 3), orientations (N, 4), query
    times (N,) and valid (N,) (False for padding)."""

    times: Array
    positions: Array
    orientations: Array
    query_times: Array
    valid: Array


# --- Kalman ------------------------------------------------------------------------------------


def _transition(order: int, dt: Array) -> tuple[Array, Array]:
    """F and Q / density of the order-n continuous white-noise model over dt."""
    if order == 2:
        f = jnp.array([[1.0, dt], [0.0, 1.0]])
        q = jnp.array([[dt**3 / 3.0, dt**2 / 2.0], [dt**2 / 2.0, dt]])
    else:
        f = jnp.array([[1.0, dt, dt * dt / 2.0], [0.0, 1.0, dt], [0.0, 0.0, 1.0]])
        q = jnp.array(
            [
                [dt**5 / 20.0, dt**4 / 8.0, dt**3 / 6.0],
                [dt**4 / 8.0, dt**3 / 3.0, dt**2 / 2.0],
                [dt**3 / 6.0, dt**2 / 2.0, dt],
            ]
        )
    return f, q


def _damped_transition(dt: Array, damping: Array) -> tuple[Array, Array, Array, Array]:
    """(reach, decay, F, Q / density) of the damped-velocity model over dt, as
    `predictors.kinematic_covariance.damped_step`, with the branch not taken kept finite (and its
    gradient too) by evaluating it at a harmless argument."""
    x = damping * dt
    decay = jnp.exp(-x)
    moving = x > 0.0
    safe_x = jnp.where(moving, x, 1.0)
    h = jnp.where(moving, -jnp.expm1(-safe_x) / safe_x, 1.0)
    series = x < SERIES_BELOW
    wide = jnp.where(series, 1.0, x)
    a = -jnp.expm1(-wide)
    closed = (wide - a - 0.5 * a * a) / (wide * wide * wide)
    g = jnp.where(
        series, 1.0 / 3.0 + x * (-0.25 + x * (7.0 / 60.0 + x * (-1.0 / 24.0 + x * (31.0 / 2520.0 - x / 320.0)))), closed
    )
    reach = dt * h
    f = jnp.array([[1.0, reach], [0.0, decay]])
    q01 = 0.5 * dt * dt * h * h
    q = jnp.array([[dt * dt * dt * g, q01], [q01, 0.5 * dt * h * (1.0 + decay)]])
    return reach, decay, f, q


def _damped_reach(h: Array, damping: Array | None) -> Array:
    """(1 - e^(-damping h)) / damping, or h without damping: `kinematic_covariance.damped_reach`."""
    if damping is None:
        return h
    x = damping * h
    moving = x != 0.0
    safe_x = jnp.where(moving, x, 1.0)
    return jnp.where(moving, h * (-jnp.expm1(-safe_x) / safe_x), h)


def _covariance_step(p: Array, f: Array, q: Array, density: Array, variance: Array) -> tuple[Array, Array]:
    """Time then measurement update of a shared per-axis covariance; returns (P, gain)."""
    p = f @ p @ f.T + density * q
    gain = p[:, 0] / (p[0, 0] + variance)
    return p - jnp.outer(gain, p[0]), gain


class _KalmanState(NamedTuple):
    started: Array
    t: Array
    state: Array  # (order, 3): position, velocity (, acceleration) per axis
    covariance: Array  # (order, order)
    q: Array
    w: Array
    orientation_covariance: Array  # (2, 2)


def _kalman_start(order: int, params: KalmanParams, t: Array, z: Array, zq: Array) -> _KalmanState:
    initial = [params.position_noise**2, jnp.asarray(INITIAL_SPEED_STD**2), jnp.asarray(INITIAL_ACCELERATION_STD**2)]
    state = jnp.zeros((order, 3)).at[0].set(z)
    orientation_initial = jnp.stack([params.orientation_noise**2, jnp.asarray(INITIAL_ANGULAR_SPEED_STD**2)])
    return _KalmanState(
        jnp.asarray(True),
        t,
        state,
        jnp.diag(jnp.stack(initial[:order])),
        zq,
        jnp.zeros(3),
        jnp.diag(orientation_initial),
    )


def _kalman_step(order: int, params: KalmanParams, s: _KalmanState, t: Array, z: Array, zq: Array) -> _KalmanState:
    dt = t - s.t
    f, q = _transition(order, dt)
    covariance, gain = _covariance_step(s.covariance, f, q, params.position_drive**2, params.position_noise**2)
    predicted = f @ s.state
    state = predicted + gain[:, None] * (z - predicted[0])[None, :]
    if params.angular_velocity_damping is None:
        f2, q2 = _transition(2, dt)
        reach, decay = dt, 1.0
    else:
        reach, decay, f2, q2 = _damped_transition(dt, params.angular_velocity_damping)
    orientation_covariance, (k0, k1) = _covariance_step(
        s.orientation_covariance, f2, q2, params.angular_acceleration_noise**2, params.orientation_noise**2
    )
    q_predicted = rotated_by(reach * s.w, s.q)
    residual = rotation_vector_between(q_predicted, zq)
    return _KalmanState(
        s.started,
        t,
        state,
        covariance,
        rotated_by(k0 * residual, q_predicted),
        decay * s.w + k1 * residual,
        orientation_covariance,
    )


def _require_float64(trace: TraceArrays) -> None:
    if trace.times.dtype != jnp.float64:
        raise PredictorError(
            f"the JAX twins need float64 times, got {trace.times.dtype}: make the arrays and run the twins "
            "inside `with jax.enable_x64(True):`"
        )


def _select(condition: Array, a: NamedTuple, b: NamedTuple) -> NamedTuple:
    return jax.tree_util.tree_map(lambda x, y: jnp.where(condition, x, y), a, b)


def kalman_predictions(order: int, params: KalmanParams, trace: TraceArrays) -> tuple[Array, Array]:
    """Predicted positions (N, 3) and orientations (N, 4) of `kalman-cv` (order 2) or `kalman-ca`
    (order 3) at trace.query_times, sample by sample. `order` is static."""
    if order not in (2, 3):
        raise ValueError(f"order must be 2 or 3, got {order!r}")
    _require_float64(trace)
    n = trace.times.shape[0]
    empty = _KalmanState(
        jnp.asarray(False), jnp.asarray(0.0), jnp.zeros((order, 3)), jnp.eye(order), jnp.array([1.0, 0.0, 0.0, 0.0]),
        jnp.zeros(3), jnp.eye(2),
    )

    def step(s: _KalmanState, k: Array) -> tuple[_KalmanState, tuple[Array, Array]]:
        t, z, zq = trace.times[k], trace.positions[k], trace.orientations[k]
        valid = trace.valid[k]
        start = ~s.started | (t - s.t > params.max_gap)
        dropped = ~start & (t < s.t)
        # Evaluate the step on a harmless time step where its result is thrown away, so that
        # neither the value nor the gradient of the discarded branch can be inf or NaN.
        stepping = valid & ~start & ~dropped
        safe = s._replace(t=jnp.where(stepping, s.t, t))
        stepped = _kalman_step(order, params, safe, t, z, zq)
        fresh = _kalman_start(order, params, t, z, zq)
        new = _select(valid & start, fresh, _select(stepping, stepped, s))
        h = jnp.clip(trace.query_times[k] - new.t, -params.max_horizon, params.max_horizon)
        powers = jnp.array([1.0, h, 0.5 * h * h])[:order]
        reach = _damped_reach(h, params.angular_velocity_damping)
        return new, (powers @ new.state, rotated_by(reach * new.w, new.q))

    _, (positions, orientations) = lax.scan(step, empty, jnp.arange(n))
    return positions, orientations


# --- DESP --------------------------------------------------------------------------------------


class _DespState(NamedTuple):
    started: Array
    t: Array
    s1: Array
    s2: Array
    q1: Array
    q2: Array
    before_s1: Array
    before_s2: Array
    before_q1: Array
    before_q2: Array
    has_before: Array
    measured_interval: Array
    has_interval: Array


def _desp_smoothed(params: DespParams, s1: Array, s2: Array, q1: Array, q2: Array, z: Array, zq: Array) -> tuple[Array, ...]:
    a = params.position_alpha
    s1 = a * z + (1.0 - a) * s1
    s2 = a * s1 + (1.0 - a) * s2
    q1 = slerp(q1, zq, params.orientation_alpha)
    q2 = slerp(q2, q1, params.orientation_alpha)
    return s1, s2, q1, q2


def desp_predictions(params: DespParams, trace: TraceArrays) -> tuple[Array, Array]:
    """Predicted positions (N, 3) and orientations (N, 4) of `desp` at trace.query_times."""
    _require_float64(trace)
    n = trace.times.shape[0]
    zero3, identity = jnp.zeros(3), jnp.array([1.0, 0.0, 0.0, 0.0])
    false = jnp.asarray(False)
    empty = _DespState(false, jnp.asarray(0.0), zero3, zero3, identity, identity, zero3, zero3, identity, identity,
                       false, jnp.asarray(1.0), false)

    def step(s: _DespState, k: Array) -> tuple[_DespState, tuple[Array, Array]]:
        t, z, zq = trace.times[k], trace.positions[k], trace.orientations[k]
        valid = trace.valid[k]
        start = ~s.started | (t - s.t > params.max_gap)
        dt = t - s.t
        dropped = ~start & (dt < 0.0)
        repeat = ~start & (dt == 0.0)
        advance = valid & ~start & ~dropped & ~repeat
        fresh = _DespState(jnp.asarray(True), t, z, z, zq, zq, z, z, zq, zq, false, s.measured_interval, s.has_interval)
        # A repeated time redoes the newest step from the state before it (or restarts).
        base = (
            jnp.where(repeat, s.before_s1, s.s1), jnp.where(repeat, s.before_s2, s.s2),
            jnp.where(repeat, s.before_q1, s.q1), jnp.where(repeat, s.before_q2, s.q2),
        )
        s1, s2, q1, q2 = _desp_smoothed(params, *base, z, zq)
        safe_dt = jnp.where(advance, dt, s.measured_interval)
        measured = jnp.where(s.has_interval, s.measured_interval + INTERVAL_RATE * (safe_dt - s.measured_interval), safe_dt)
        advanced = _DespState(jnp.asarray(True), t, s1, s2, q1, q2, s.s1, s.s2, s.q1, s.q2, jnp.asarray(True),
                              measured, jnp.asarray(True))
        redone = s._replace(s1=s1, s2=s2, q1=q1, q2=q2)
        restarted = fresh._replace(t=s.t)
        new = _select(
            valid & start, fresh,
            _select(advance, advanced,
                    _select(valid & repeat, _select(s.has_before, redone, restarted), s)),
        )
        given = params.sample_interval > 0.0
        interval = jnp.where(given, params.sample_interval, new.measured_interval)
        known = given | new.has_interval
        h = jnp.clip(trace.query_times[k] - new.t, -params.max_horizon, params.max_horizon)
        tau = jnp.where(known, h / jnp.where(known, interval, 1.0), 0.0)
        a = params.position_alpha
        position = new.s1 + (1.0 + a * tau / (1.0 - a)) * (new.s1 - new.s2)
        ao = params.orientation_alpha
        orientation = slerp(new.q2, new.q1, 2.0 + ao * tau / (1.0 - ao))
        return new, (position, orientation)

    _, (positions, orientations) = lax.scan(step, empty, jnp.arange(n))
    return positions, orientations


def predictions(predictor: str, values: Mapping[str, Any], trace: TraceArrays) -> tuple[Array, Array]:
    """Predicted positions (N, 3) and orientations (N, 4) of the twin of `predictor` (one of
    `TWINNED`), given every one of its parameters by declared name (`params_of(predictor).resolve`
    gives them; any may be a traced JAX scalar)."""
    if predictor == "desp":
        return desp_predictions(desp_params(values), trace)
    if predictor not in _KALMAN_ORDERS:
        raise PredictorError(f"{predictor!r} has no JAX twin; twinned predictors: {', '.join(TWINNED)}")
    order = _KALMAN_ORDERS[predictor]
    return kalman_predictions(order, kalman_params(order, values), trace)
