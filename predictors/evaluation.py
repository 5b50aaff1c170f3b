"""Replay a trace through a predictor and score its predictions at chosen horizons.

At every sample, in the order the host received them, the predictor takes the sample and is asked
for the pose `horizon` seconds after the sample's arrival (with no transport delay, after its sensor
time): the moment a display frame using it would light up. Each prediction is compared with the
trace's truth at that time; predictions past the end of the truth are not scored.

Scores per horizon: position error RMS, 95th percentile and maximum (mm); angular error RMS, 95th
percentile and maximum (deg); jitter, the RMS of the second difference of the predicted motion
(mm and deg per sample: what shakes on the display); and, per predictor, microseconds per
update plus one predict, the best of a few timed replays, in CPU time of this process: on a shared
machine, time other jobs take from it would count as the predictor's in wall-clock time.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from predictors import quaternion
from predictors.errors import PredictorError
from predictors.registry import Predictor, make
from predictors.trace import Trace

DEFAULT_HORIZONS_S = (0.0, 0.01, 0.02, 0.05, 0.1)


@dataclass(frozen=True)
class HorizonScore:
    """Errors of the predictions made `horizon_ms` ahead; count is how many were scored."""

    horizon_ms: float
    count: int
    position_rms_mm: float
    position_p95_mm: float
    position_max_mm: float
    angular_rms_deg: float
    angular_p95_deg: float
    angular_max_deg: float
    position_jitter_mm: float
    angular_jitter_deg: float


@dataclass(frozen=True)
class Evaluation:
    """A predictor's scores on one trace."""

    predictor: str
    params: dict[str, Any]
    trace: str
    samples: int
    us_per_update: float
    scores: tuple[HorizonScore, ...] = field(default_factory=tuple)

    def at(self, horizon_ms: float) -> HorizonScore:
        """The score at a horizon (ms)."""
        for score in self.scores:
            if math.isclose(score.horizon_ms, horizon_ms, abs_tol=1e-9):
                return score
        raise PredictorError(f"{self.predictor} was not scored at {horizon_ms:g} ms; scored at "
                             f"{', '.join(f'{s.horizon_ms:g}' for s in self.scores)} ms")

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-ready values."""
        return asdict(self)


def replay(predictor: Predictor, trace: Trace, horizons_s: Sequence[float]) -> tuple[np.ndarray, ...]:
    """Feed the trace to `predictor` (reset first) and predict at every horizon after every sample.

    Returns query times (H, N), positions (H, N, 3) and orientations (H, N, 4), samples in arrival
    order.
    """
    predictor.reset()
    samples = trace.samples()
    arrivals = np.array([s.t_arrival for s in samples])
    queries = arrivals[None, :] + np.asarray(horizons_s, dtype=np.float64)[:, None]
    positions = np.empty(queries.shape + (3,))
    orientations = np.empty(queries.shape + (4,))
    query_rows = queries.T.tolist()
    for k, (sample, row) in enumerate(zip(samples, query_rows)):
        predictor.update(sample)
        for j, t in enumerate(row):
            pose = predictor.predict(t)
            positions[j, k] = pose.position
            orientations[j, k] = pose.orientation
    return queries, positions, orientations


def time_per_update(predictor: Predictor, trace: Trace, horizon_s: float, repeats: int = 3) -> float:
    """CPU microseconds per update plus one predict, the best of `repeats` replays (samples
    pre-built); infinite for no replay."""
    samples = trace.samples()
    queries = [s.t_arrival + horizon_s for s in samples]
    best = math.inf
    for _ in range(repeats):
        predictor.reset()
        update, predict = predictor.update, predictor.predict
        start = time.process_time()
        for sample, t in zip(samples, queries):
            update(sample)
            predict(t)
        best = min(best, time.process_time() - start)
    return 1e6 * best / max(len(samples), 1)


def _jitter(position: np.ndarray, orientation: np.ndarray) -> tuple[float, float]:
    if position.shape[0] < 3:
        return 0.0, 0.0
    second = position[2:] - 2.0 * position[1:-1] + position[:-2]
    steps = quaternion.to_rotation_vector(quaternion.multiply(orientation[1:], quaternion.conjugate(orientation[:-1])))
    turn = steps[1:] - steps[:-1]
    return (
        1e3 * float(np.sqrt(np.mean(np.sum(second**2, axis=1)))),
        math.degrees(float(np.sqrt(np.mean(np.sum(turn**2, axis=1))))),
    )


def _summary(errors: np.ndarray, scale: float) -> tuple[float, float, float]:
    if errors.size == 0:
        return math.nan, math.nan, math.nan
    return (
        scale * float(np.sqrt(np.mean(errors**2))),
        scale * float(np.percentile(errors, 95)),
        scale * float(np.max(errors)),
    )


def score(trace: Trace, horizons_s: Sequence[float], queries: np.ndarray, positions: np.ndarray,
          orientations: np.ndarray) -> tuple[HorizonScore, ...]:
    """Scores of predictions (as `replay` returns them) against the trace's truth."""
    scores = []
    for j, horizon in enumerate(horizons_s):
        scored = trace.covers(queries[j])
        true_position, true_orientation = trace.truth_at(queries[j][scored])
        position, orientation = positions[j][scored], orientations[j][scored]
        position_error = np.linalg.norm(position - true_position, axis=1)
        angular_error = quaternion.angle_between(orientation, true_orientation)
        jitter = _jitter(position, orientation)
        scores.append(
            HorizonScore(
                1e3 * float(horizon),
                int(scored.sum()),
                *_summary(position_error, 1e3),
                *_summary(angular_error, math.degrees(1.0)),
                *jitter,
            )
        )
    return tuple(scores)


def evaluate(
    predictor: str,
    trace: Trace,
    horizons_s: Sequence[float] = DEFAULT_HORIZONS_S,
    params: Mapping[str, Any] | None = None,
    timing_repeats: int = 3,
) -> Evaluation:
    """Scores of predictor `predictor` (made with `params`) on `trace` at every horizon (s)."""
    params = dict(params or {})
    instance = make(predictor, **params)
    if not horizons_s:
        raise PredictorError("evaluate needs at least one horizon")
    queries, positions, orientations = replay(instance, trace, horizons_s)
    scores = score(trace, horizons_s, queries, positions, orientations)
    cost = time_per_update(instance, trace, float(horizons_s[0]), timing_repeats)
    return Evaluation(predictor, params, trace.name, len(trace), cost, scores)
