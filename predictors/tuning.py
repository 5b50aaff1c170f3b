"""Fit a predictor's parameters to recorded motion: minimise prediction error at one horizon.

The loss is the mean squared position error (m^2) plus the mean squared angular error (rad^2, as
4 sin^2(angle / 2), smooth and the same for q and -q) of the predictions made `horizon` after every
sample of the training traces, each term divided by its value at the starting parameters so that
metres and radians weigh alike (a trace without position motion drops its position term). It is
computed by the JAX twins (`predictors.jax_filters`), vmapped over the traces, and minimised by
`predictors.optimizer` in unconstrained coordinates. What is fitted, and how, each predictor's
parameter declaration says (`predictors.registry.params_of`): the `trainable` parameters, mapped
by their `transform` (log or logit) and started from `tune_from` where the transform cannot take
the value given (a damping of 0); the rest stay as given. A trained parameter is reported as
fitted only where the part of the pose it `acts_on` moved in the traces.

* `kalman-cv` / `kalman-ca`: the process noises (acceleration_noise or jerk_noise, and
  angular_acceleration_noise) and angular_velocity_damping. The predicted means depend on process
  and measurement noise only through their ratio, so the measurement noises stay as given (the
  tracker's datasheet values, or the defaults). The damping is a rate, not a noise: it shapes how
  far a velocity carries, which no noise ratio can;
* `desp`: position_alpha and orientation_alpha;
* `auto`: the parameters it shares with `kalman-cv`, fitted as kalman-cv's, then its other
  trainable ones, `memory` and `margin`, which choose between models and so move the loss in steps
  that no gradient sees, by the same loss (scaled as the filters' fit scaled it) over a grid
  (`AUTO_MEMORY_GRID_S` x `AUTO_MARGIN_GRID` and the starting values), each point scored by
  replaying the real-time `auto`.

Importing this module imports JAX and changes none of its settings: `tune` computes in float64
inside `jax.enable_x64(True)` (see `predictors.jax_filters`), restoring the caller's setting.
"""

from __future__ import annotations

import itertools
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
from predictors.params import Transform
from predictors.registry import make, params_of
from predictors.trace import Trace

TUNABLE = (*jax_filters.TWINNED, "auto")

# auto's score time constant (s) and margin (fraction), searched on this grid (log-spaced: both act
# multiplicatively) plus the starting values: its trainable parameters that kalman-cv has not.
AUTO_MEMORY_GRID_S = (0.1, 0.2, 0.5, 1.0, 2.0)
AUTO_MARGIN_GRID = (0.05, 0.1, 0.2, 0.4)
AUTO_GRIDS = {"memory": AUTO_MEMORY_GRID_S, "margin": AUTO_MARGIN_GRID}


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
    """Maps an unconstrained vector to a predictor's parameters and its JAX predictions: the
    trainable parameters (each with a transform, as `Param` ensures) through their transforms, the
    others fixed at `base` or their defaults."""

    def __init__(self, predictor: str, base: Mapping[str, Any]) -> None:
        declared = params_of(predictor)
        self.predictor = predictor
        self.values = declared.resolve(base)
        self.base = dict(base)
        self.trained = declared.trainable
        # Runs of consecutive trained parameters under one transform, each mapped as one slice of x:
        # one vectorised transform per run is the computation (and so the rounding) of the fit.
        self.runs: list[tuple[int, int, Transform]] = []
        for transform, run in itertools.groupby(enumerate(self.trained), key=lambda item: item[1].transform):
            indices = [i for i, _ in run]
            self.runs.append((indices[0], indices[-1] + 1, transform))

    def start(self) -> np.ndarray:
        """The unconstrained starting point: each trained value, or its `tune_from` where the
        transform cannot take it."""
        start = []
        for param in self.trained:
            transform, value = param.transform, self.values[param.name]
            if not transform.domain.contains(value):
                value = param.tune_from
            start.append(transform.to_unconstrained(value))
        return np.array(start)

    def natural(self, x: np.ndarray) -> dict[str, float]:
        """The fitted values; one the fit took past its declared range (a noise ratio the trace does
        not bound: the loss is flat there) is held at the range's end, so the parameters load back."""
        return {param.name: param.range.clipped(float(param.transform.to_natural(v))) for param, v in zip(self.trained, x)}

    def predictions(self) -> Callable[[jax.Array, jax_filters.TraceArrays], tuple[jax.Array, jax.Array]]:
        fixed, trained, runs, predictor = self.values, self.trained, self.runs, self.predictor

        def predict(x: jax.Array, trace: jax_filters.TraceArrays) -> tuple[jax.Array, jax.Array]:
            values = dict(fixed)
            for start, stop, transform in runs:
                natural = transform.to_natural_jax(x[start:stop])
                values.update((trained[i].name, natural[i - start]) for i in range(start, stop))
            return jax_filters.predictions(predictor, values, trace)

        return predict


@dataclass(frozen=True)
class _Fit:
    """A gradient fit, and the scales that make its loss unitless (1 / each term at the start)."""

    result: TuneResult
    position_scale: float
    angular_scale: float


Progress = Callable[[float, float], object]  # called as progress(done, total)


def _fit(predictor: str, traces: Sequence[Trace], horizon_s: float, params: Mapping[str, Any],
         max_iterations: int, progress: Callable[[int], object] | None = None) -> _Fit:
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

    best = minimise(loss, x0, max_iterations=max_iterations, progress=progress)
    fitted = model.natural(best.x)
    scales = {"position": position_scale, "orientation": angular_scale, "pose": max(position_scale, angular_scale)}
    informed = tuple(param.name for param in model.trained if scales[param.acts_on] > 0.0)
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


def _tune_auto(traces: Sequence[Trace], horizon_s: float, params: Mapping[str, Any], max_iterations: int,
               progress: Progress | None) -> TuneResult:
    """auto's filters as kalman-cv's by gradient, then memory and margin on a grid (module docstring)."""
    start = params_of("auto").resolve(params)
    axes = [sorted({*grid, start[name]}) for name, grid in AUTO_GRIDS.items()]
    total = max_iterations + math.prod(len(axis) for axis in axes)
    filter_names = params_of("kalman-cv").names
    shared = {name: value for name, value in params.items() if name in filter_names}
    filters = _fit("kalman-cv", traces, horizon_s, shared, max_iterations, _iterations(progress, total))
    scales = (filters.position_scale, filters.angular_scale)
    fitted = {name: filters.result.params[name] for name in filters.result.fitted}
    candidates = [{**params, **fitted, **dict(zip(AUTO_GRIDS, point))} for point in itertools.product(*axes)]
    losses = []
    for k, candidate in enumerate(candidates):
        losses.append(_replayed_loss("auto", candidate, traces, horizon_s, *scales))
        if progress is not None:
            progress(max_iterations + k + 1, total)
    best = int(np.argmin(losses))
    return TuneResult(
        "auto", candidates[best], (*filters.result.fitted, *AUTO_GRIDS), float(horizon_s),
        _replayed_loss("auto", params, traces, horizon_s, *scales), losses[best], filters.result.iterations,
    )


def _iterations(progress: Progress | None, total: int) -> Callable[[int], object] | None:
    """The optimiser's per-iteration callback reporting to `progress` out of `total` steps."""
    return None if progress is None else lambda done: progress(done, total)


def tune(
    predictor: str,
    traces: Sequence[Trace],
    horizon_s: float,
    params: Mapping[str, Any] | None = None,
    max_iterations: int = 40,
    progress: Progress | None = None,
) -> TuneResult:
    """Fit `predictor`'s parameters (starting from `params`, else its defaults) to predict the
    training `traces` `horizon_s` seconds ahead, in float64 whatever the caller's JAX setting.
    `progress(done, total)` is told of each optimiser iteration (and, for auto, grid point)."""
    if predictor not in TUNABLE:
        raise PredictorError(f"cannot tune {predictor!r}; tunable predictors: {', '.join(TUNABLE)}")
    if not traces:
        raise PredictorError("tuning needs at least one training trace")
    if not (math.isfinite(horizon_s) and horizon_s >= 0.0):
        raise PredictorError(f"the horizon must be zero or a positive number of seconds, got {horizon_s!r}")
    with jax.enable_x64(True):
        if predictor == "auto":
            return _tune_auto(traces, horizon_s, params or {}, max_iterations, progress)
        return _fit(predictor, traces, horizon_s, params or {}, max_iterations, _iterations(progress, max_iterations)).result
