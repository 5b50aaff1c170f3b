"""Fit a predictor's parameters to recorded motion: minimise prediction error at one horizon.

The loss is the mean squared position error (m^2) plus the mean squared angular error (rad^2, as
4 sin^2(angle / 2), smooth and the same for q and -q) of the predictions made `horizon` after every
sample of the training traces, each term divided by its value at the starting parameters so that
metres and radians weigh alike (a trace without position motion drops its position term). It is
computed by the JAX twins (`predictors.jax_filters`), vmapped over the traces, and minimised by
`predictors.optimizer` in unconstrained coordinates:

* `kalman-cv` / `kalman-ca`: the logarithms of the process noises (acceleration_noise or
  jerk_noise, and angular_acceleration_noise) and of angular_velocity_damping. The predicted
  means depend on process and measurement noise only through their ratio, so the measurement
  noises stay as given (the tracker's datasheet values, or the defaults) and only the process
  noises are fitted. The damping is a rate, not a noise: it shapes how far a velocity carries,
  which no noise ratio can, and is fitted beside them (from `DAMPING_START` when the start has no
  damping: log 0 is no starting point, and a one-second time constant predicts almost as the
  undamped model at the horizons tuned for while giving the loss a slope in it);
* `desp`: the logits of position_alpha and orientation_alpha;
* `auto`: its filters' parameters as `kalman-cv` (jerk_noise stays as given: tune `kalman-ca`
  for it), then `memory` and `margin`, which choose between models and so move the loss in steps
  that no gradient sees, by the same loss (scaled as the filters' fit scaled it) over a grid
  (`AUTO_MEMORY_GRID_S` x `AUTO_MARGIN_GRID` and the starting values), each point scored by
  replaying the real-time `auto`.

Importing this module imports JAX and switches it to float64 (see `predictors.jax_filters`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

import jax
import jax.numpy as jnp
import numpy as np

from predictors import jax_filters
from predictors.errors import PredictorError
from predictors.evaluation import replay
from predictors.optimizer import minimise
from predictors.registry import make
from predictors.trace import Trace

TUNABLE = ("kalman-cv", "kalman-ca", "desp", "auto")

# Where the damping search starts when the starting parameters have none (1/s).
DAMPING_START = 1.0
# The parameters `auto` shares with `kalman-cv`, fitted as kalman-cv's.
AUTO_FILTER_PARAMS = (
    "position_noise", "acceleration_noise", "orientation_noise", "angular_acceleration_noise",
    "angular_velocity_damping", "max_gap", "max_horizon",
)
# auto's score time constant (s) and margin (fraction), searched on this grid (log-spaced: both act
# multiplicatively) plus the starting values.
AUTO_MEMORY_GRID_S = (0.1, 0.2, 0.5, 1.0, 2.0)
AUTO_MARGIN_GRID = (0.05, 0.1, 0.2, 0.4)


@dataclass(frozen=True)
class TuneResult:
    """Fitted parameters (all of them, ready for `make`), which ones were fitted, and the loss at
    the start of the search and at its end (iterations: the gradient search's)."""

    predictor: str
    params: dict[str, Any]
    fitted: tuple[str, ...]
    horizon_s: float
    loss_before: float
    loss_after: float
    iterations: int


def _stacked(traces: Sequence[Trace], horizon_s: float) -> tuple[jax_filters.TraceArrays, np.ndarray, np.ndarray, np.ndarray]:
    """The traces padded to one length, in arrival order, with the truth at every query time and
    the mask of scored predictions."""
    length = max(len(trace) for trace in traces)
    columns: dict[str, list[np.ndarray]] = {k: [] for k in ("t", "p", "q", "query", "valid", "true_p", "true_q", "scored")}
    for trace in traces:
        order = trace.arrival_order()
        pad = length - len(trace)
        query = trace.t_arrival[order] + horizon_s
        true_p, true_q = trace.truth_at(query)
        columns["t"].append(np.pad(trace.t[order], (0, pad), mode="edge"))
        columns["p"].append(np.pad(trace.position[order], ((0, pad), (0, 0)), mode="edge"))
        columns["q"].append(np.pad(trace.orientation[order], ((0, pad), (0, 0)), mode="edge"))
        columns["query"].append(np.pad(query, (0, pad), mode="edge"))
        columns["valid"].append(np.arange(length) < len(trace))
        columns["true_p"].append(np.pad(true_p, ((0, pad), (0, 0)), mode="edge"))
        columns["true_q"].append(np.pad(true_q, ((0, pad), (0, 0)), mode="edge"))
        columns["scored"].append(np.pad(trace.covers(query), (0, pad)))
    stack = {k: np.stack(v) for k, v in columns.items()}
    arrays = jax_filters.TraceArrays(
        jnp.asarray(stack["t"]), jnp.asarray(stack["p"]), jnp.asarray(stack["q"]), jnp.asarray(stack["query"]),
        jnp.asarray(stack["valid"]),
    )
    return arrays, stack["true_p"], stack["true_q"], stack["scored"]


class _Parameterisation:
    """Maps an unconstrained vector to a predictor's parameters and its JAX predictions."""

    def __init__(self, predictor: str, base: Mapping[str, Any]) -> None:
        self.predictor = predictor
        self.instance = make(predictor, **base)
        self.base = dict(base)
        if predictor == "desp":
            self.names: tuple[str, ...] = ("position_alpha", "orientation_alpha")
        else:
            drive = "acceleration_noise" if predictor == "kalman-cv" else "jerk_noise"
            self.names = (drive, "angular_acceleration_noise", "angular_velocity_damping")

    def start(self) -> np.ndarray:
        values = np.array([getattr(self.instance, name) for name in self.names])
        if self.predictor == "desp":
            return np.log(values / (1.0 - values))
        values[-1] = values[-1] or DAMPING_START
        return np.log(values)

    def natural(self, x: np.ndarray) -> dict[str, float]:
        values = 1.0 / (1.0 + np.exp(-x)) if self.predictor == "desp" else np.exp(x)
        return {name: float(v) for name, v in zip(self.names, values)}

    def predictions(self) -> Callable[[jax.Array, jax_filters.TraceArrays], tuple[jax.Array, jax.Array]]:
        p = self.instance
        if self.predictor == "desp":
            interval = 0.0 if p.sample_interval is None else p.sample_interval

            def run_desp(x: jax.Array, trace: jax_filters.TraceArrays) -> tuple[jax.Array, jax.Array]:
                alphas = jax.nn.sigmoid(x)
                params = jax_filters.DespParams(alphas[0], alphas[1], jnp.asarray(interval), jnp.asarray(p.max_gap),
                                                jnp.asarray(p.max_horizon))
                return jax_filters.desp_predictions(params, trace)

            return run_desp
        order = 2 if self.predictor == "kalman-cv" else 3

        def run_kalman(x: jax.Array, trace: jax_filters.TraceArrays) -> tuple[jax.Array, jax.Array]:
            values = jnp.exp(x)
            params = jax_filters.KalmanParams(
                jnp.asarray(p.position_noise), values[0], jnp.asarray(p.orientation_noise), values[1],
                jnp.asarray(p.max_gap), jnp.asarray(p.max_horizon), values[2],
            )
            return jax_filters.kalman_predictions(order, params, trace)

        return run_kalman


@dataclass(frozen=True)
class _Fit:
    """A gradient fit, and the scales that make its loss unitless (1 / each term at the start)."""

    result: TuneResult
    position_scale: float
    angular_scale: float


def _fit(predictor: str, traces: Sequence[Trace], horizon_s: float, params: Mapping[str, Any],
         max_iterations: int) -> _Fit:
    """Fit a JAX-twinned predictor's parameters (see the module docstring) by gradient."""
    model = _Parameterisation(predictor, params)
    arrays, true_p, true_q, scored = _stacked(traces, horizon_s)
    weight = jnp.asarray(scored, dtype=jnp.float64) / max(int(scored.sum()), 1)
    true_p, true_q = jnp.asarray(true_p), jnp.asarray(true_q)
    run = jax.vmap(model.predictions(), in_axes=(None, 0))

    def errors(x: jax.Array) -> tuple[jax.Array, jax.Array]:
        positions, orientations = run(x, arrays)
        position = jnp.sum(weight * jnp.sum((positions - true_p) ** 2, axis=-1))
        dot = jnp.sum(orientations * true_q, axis=-1)
        angular = jnp.sum(weight * 4.0 * (1.0 - dot * dot))
        return position, angular

    x0 = model.start()
    position0, angular0 = (float(e) for e in jax.jit(errors)(jnp.asarray(x0)))
    position_scale = 1.0 / position0 if position0 > 0.0 else 0.0
    angular_scale = 1.0 / angular0 if angular0 > 0.0 else 0.0

    def loss(x: jax.Array) -> jax.Array:
        position, angular = errors(x)
        return position_scale * position + angular_scale * angular

    best = minimise(loss, x0, max_iterations=max_iterations)
    fitted = model.natural(best.x)
    informed = tuple(
        name for name in model.names
        if (position_scale if name in ("acceleration_noise", "jerk_noise", "position_alpha") else angular_scale) > 0.0
    )
    values = {**model.base, **{name: fitted[name] for name in informed}}
    result = TuneResult(predictor, values, informed, float(horizon_s),
                        float(position_scale * position0 + angular_scale * angular0), best.value, best.iterations)
    return _Fit(result, position_scale, angular_scale)


def _replayed_loss(predictor: str, params: Mapping[str, Any], traces: Sequence[Trace], horizon_s: float,
                   position_scale: float, angular_scale: float) -> float:
    """The tuning loss of the real-time predictor, replayed on the traces (for what JAX cannot
    differentiate)."""
    instance = make(predictor, **params)
    position = angular = 0.0
    count = 0
    for trace in traces:
        queries, positions, orientations = replay(instance, trace, [horizon_s])
        scored = trace.covers(queries[0])
        true_p, true_q = trace.truth_at(queries[0][scored])
        position += float(np.sum((positions[0][scored] - true_p) ** 2))
        dot = np.sum(orientations[0][scored] * true_q, axis=-1)
        angular += float(np.sum(4.0 * (1.0 - dot * dot)))
        count += int(scored.sum())
    return (position_scale * position + angular_scale * angular) / max(count, 1)


def _tune_auto(traces: Sequence[Trace], horizon_s: float, params: Mapping[str, Any], max_iterations: int) -> TuneResult:
    """auto's filters as kalman-cv's by gradient, then memory and margin on a grid (module docstring)."""
    start = make("auto", **params)
    shared = {name: value for name, value in params.items() if name in AUTO_FILTER_PARAMS}
    filters = _fit("kalman-cv", traces, horizon_s, shared, max_iterations)
    scales = (filters.position_scale, filters.angular_scale)
    fitted = {name: filters.result.params[name] for name in filters.result.fitted}
    candidates = [
        {**params, **fitted, "memory": memory, "margin": margin}
        for memory in sorted({*AUTO_MEMORY_GRID_S, start.memory})
        for margin in sorted({*AUTO_MARGIN_GRID, start.margin})
    ]
    losses = [_replayed_loss("auto", candidate, traces, horizon_s, *scales) for candidate in candidates]
    best = int(np.argmin(losses))
    return TuneResult(
        "auto", candidates[best], (*filters.result.fitted, "memory", "margin"), float(horizon_s),
        _replayed_loss("auto", params, traces, horizon_s, *scales), losses[best], filters.result.iterations,
    )


def tune(
    predictor: str,
    traces: Sequence[Trace],
    horizon_s: float,
    params: Mapping[str, Any] | None = None,
    max_iterations: int = 40,
) -> TuneResult:
    """Fit `predictor`'s parameters (starting from `params`, else its defaults) to predict the
    training `traces` `horizon_s` seconds ahead."""
    if predictor not in TUNABLE:
        raise PredictorError(f"cannot tune {predictor!r}; tunable predictors: {', '.join(TUNABLE)}")
    if not traces:
        raise PredictorError("tuning needs at least one training trace")
    if not (math.isfinite(horizon_s) and horizon_s >= 0.0):
        raise PredictorError(f"the horizon must be zero or a positive number of seconds, got {horizon_s!r}")
    if predictor == "auto":
        return _tune_auto(traces, horizon_s, params or {}, max_iterations)
    return _fit(predictor, traces, horizon_s, params or {}, max_iterations).result
