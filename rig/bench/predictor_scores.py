"""The predictor bench's scores (`rig.bench.predictors`): each predictor's RMS errors over those of
constant velocity from the last two samples (BASELINE), its cost over another's, and its score
tuned on every trace but the one it is scored on."""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial
from typing import Any, Callable, Sequence

from predictors import Evaluation, PredictorError, Trace, evaluate
from predictors.cross_validation import PARTS, CorpusScores
from rig import interrupts
from rig.bench.predictors_settings import BASELINE


@dataclass(frozen=True)
class FailedEvaluation:
    """A predictor that could not be scored on a trace, and why: a row of the bench beside the scores."""

    predictor: str
    trace: str
    failed: str

    def to_dict(self) -> dict[str, str]:
        return {"trace": self.trace, "predictor": self.predictor, "failed": self.failed}


def failure_reason(error: Exception) -> str:
    """Why an evaluation failed, in one line: a predictor's refusal as it says it, anything else with its kind."""
    return str(error) if isinstance(error, PredictorError) else f"{type(error).__name__}: {error}"


def label(name: str, params: dict[str, Any]) -> str:
    """A predictor spec as one word: its name, and its parameters where any were given."""
    return name if not params else f"{name}:" + ",".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in params.items())


def evaluate_all(
    traces: Sequence[Trace],
    specs: Sequence[tuple[str, dict[str, Any]]],
    horizons: Sequence[float],
    timing_repeats: int,
    progress: Callable[[float, float], object] | None = None,
    failures: list[FailedEvaluation] | None = None,
) -> list[Evaluation]:
    """Every predictor spec on every trace. Given `failures`, an evaluation that raises is added
    there with its reason and the others still run (a predictor that cannot score a trace is a
    result of the bench); without it, the error propagates."""
    results = []
    total = len(traces) * len(specs)
    for i, trace in enumerate(traces):
        for j, (name, params) in enumerate(specs):
            try:
                results.append(evaluate(name, trace, [h / 1e3 for h in horizons], params, timing_repeats))
            except Exception as error:
                if failures is None:
                    raise
                failures.append(FailedEvaluation(label(name, params), trace.name, failure_reason(error)))
            if progress is not None:
                progress(i * len(specs) + j + 1, total)
    return results


def scores_of(results: Sequence[Evaluation], horizons: Sequence[float]) -> CorpusScores:
    """The evaluations by predictor label then trace, scored against BASELINE with its defaults
    (`predictors.cross_validation.CorpusScores`: each ratio, their geometric mean and worst)."""
    evaluations: dict[str, dict[str, Evaluation]] = {}
    for result in results:
        evaluations.setdefault(label(result.predictor, result.params), {})[result.trace] = result
    return CorpusScores(evaluations, BASELINE, tuple(horizons))


def finite_or_none(value: float) -> float | None:
    """The value, or None (JSON's null) where it is not finite."""
    return value if math.isfinite(value) else None


def by_horizon(value: Callable[[float], float], horizons: Sequence[float]) -> dict[str, float | None]:
    """`value` at each horizon (ms), keyed as JSON holds it, None where it is not finite."""
    return {f"{h:g}": finite_or_none(value(h)) for h in horizons}


def ratios_record(scores: CorpusScores) -> list[dict[str, Any]]:
    """Per predictor, its angular and position ratios to the baseline on each trace it was scored
    on, its cost there, and the geometric mean and worst of each part over those traces, at every
    horizon, as JSON-ready values."""
    record = []
    for name, on in scores.evaluations.items():
        traces, at = list(on), scores.horizons_ms
        record.append({
            "predictor": name,
            **{part: {t: by_horizon(partial(scores.ratio, name, t, part), at) for t in traces} for part in PARTS},
            "us_per_update": {t: evaluation.us_per_update for t, evaluation in on.items()},
            "geometric_mean": {part: by_horizon(partial(scores.group_ratio, name, traces, part), at) for part in PARTS},
            "worst": {part: by_horizon(partial(scores.worst, name, traces, part), at) for part in PARTS},
        })
    return record


def _ratio(error: float, baseline: float) -> float:
    return error / baseline if baseline > 0.0 else math.nan


def cost_ratios(results: Sequence[Evaluation]) -> dict[str, float]:
    """kalman-cv's us/update over desp's, per trace where both ran."""
    cost = {(r.trace, r.predictor): r.us_per_update for r in results}
    return {
        trace: cost[(trace, "kalman-cv")] / cost[(trace, "desp")]
        for trace, name in cost
        if name == "kalman-cv" and (trace, "desp") in cost
    }


@dataclass(frozen=True)
class HeldOut:
    """A predictor tuned at `horizon_ms` on every trace but `trace`, scored on `trace`: its angular
    and position RMS error there over constant velocity's, and its defaults' ratios beside them; or,
    where the tuning or a score raised, NaN ratios and why (`failed`)."""

    predictor: str
    trace: str
    horizon_ms: float
    params: dict[str, Any]
    angular: float
    position: float
    defaults_angular: float
    defaults_position: float
    failed: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-ready values (None for a ratio on a trace without that part)."""
        return {k: finite_or_none(v) if isinstance(v, float) else v for k, v in vars(self).items()}


def _held_out(name: str, trace: Trace, others: Sequence[Trace], horizon_ms: float, max_iterations: int) -> HeldOut:
    """`name` tuned on `others` and scored on `trace`, against its defaults and the baseline."""
    with interrupts.deferred():  # an interrupt inside jaxlib's extension init would abort the process
        from predictors.tuning import tune  # imports JAX: only when asked

    horizon = horizon_ms / 1e3
    params = tune(name, others, horizon, max_iterations=max_iterations).params
    scores = {
        key: evaluate(predictor, trace, [horizon], given, timing_repeats=0).scores[0]
        for key, predictor, given in (("tuned", name, params), ("defaults", name, {}), ("baseline", BASELINE, {}))
    }
    base = scores["baseline"]
    return HeldOut(
        name, trace.name, horizon_ms, params,
        _ratio(scores["tuned"].angular_rms_deg, base.angular_rms_deg),
        _ratio(scores["tuned"].position_rms_mm, base.position_rms_mm),
        _ratio(scores["defaults"].angular_rms_deg, base.angular_rms_deg),
        _ratio(scores["defaults"].position_rms_mm, base.position_rms_mm),
    )


def leave_one_out(
    name: str, traces: Sequence[Trace], horizon_ms: float, max_iterations: int,
    progress: Callable[[float, float], object] | None = None,
) -> list[HeldOut]:
    """Tune `name` on all traces but one and score it on that one, for each trace in turn; a fold
    that raises is a failed `HeldOut` with its reason, and the others still run."""
    held = []
    for k, trace in enumerate(traces):
        others = [t for i, t in enumerate(traces) if i != k]
        try:
            held.append(_held_out(name, trace, others, horizon_ms, max_iterations))
        except Exception as error:
            held.append(HeldOut(name, trace.name, horizon_ms, {}, math.nan, math.nan, math.nan, math.nan, failure_reason(error)))
        if progress is not None:
            progress(k + 1, len(traces))
    return held
