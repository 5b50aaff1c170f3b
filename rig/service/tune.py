"""Fit a predictor's parameters to recorded motion, and report its error on motion held out.

Training traces are given; held-out traces are given too, or, without any, the last part of each
training trace (`split` says how much is kept for training). The fitted parameters are written as
a file that `rig simulate --predictor NAME:FILE.json`, `rig bench predictors --predictor
NAME:FILE.json` and `predictors.make(name, **predictors.read_params(FILE)[1])` accept.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Sequence

from predictors import Trace, evaluate, write_params

if TYPE_CHECKING:
    from predictors.tuning import TuneResult

COMPARED_WITH = "slerp"
"""The baseline the tuned predictor is compared with on the held-out traces."""


@dataclass(frozen=True)
class TuneReport:
    """The fit (`predictors.tuning.TuneResult`) and the held-out RMS errors of the tuned predictor,
    its starting parameters and the baseline, each {"angular_rms_deg", "position_rms_mm"}."""

    fit: TuneResult
    train: list[str]
    held_out: list[str]
    held_out_samples: int
    comparison: dict[str, dict[str, float]]

    def write(self, path: Path, horizon_ms: float) -> None:
        write_params(
            path,
            self.fit.predictor,
            self.fit.params,
            horizon_ms=horizon_ms,
            fitted=list(self.fit.fitted),
            train=self.train,
            held_out={"traces": self.held_out, **self.comparison},
        )


def held_out_rms(name: str, params: dict[str, Any], traces: Sequence[Trace], horizon_s: float) -> dict[str, float]:
    """Angular (deg) and position (mm) RMS error over the traces, weighted by count."""
    scores = [evaluate(name, trace, [horizon_s], params, timing_repeats=1).scores[0] for trace in traces]
    count = sum(s.count for s in scores)
    angular = (sum(s.count * s.angular_rms_deg**2 for s in scores) / count) ** 0.5
    position = (sum(s.count * s.position_rms_mm**2 for s in scores) / count) ** 0.5
    return {"angular_rms_deg": angular, "position_rms_mm": position}


def split_traces(traces: Sequence[Trace], held_out: Sequence[Trace], split: float) -> tuple[list[Trace], list[Trace]]:
    """(training, held-out): the given held-out traces, else the end of each training trace."""
    if held_out:
        return list(traces), list(held_out)
    halves = [trace.split(split) for trace in traces]
    return [h[0] for h in halves], [h[1] for h in halves]


def tune(
    name: str,
    start: dict[str, Any],
    train: Sequence[Trace],
    held_out: Sequence[Trace],
    horizon_s: float,
    max_iterations: int,
) -> TuneReport:
    """Fit `name` from `start` on `train` at `horizon_s`; score it on `held_out`."""
    from predictors.tuning import tune as fit  # imports JAX: only when tuning

    result = fit(name, list(train), horizon_s, start, max_iterations=max_iterations)
    comparison = {
        f"{name} tuned": held_out_rms(name, result.params, held_out, horizon_s),
        f"{name} start": held_out_rms(name, start, held_out, horizon_s),
        COMPARED_WITH: held_out_rms(COMPARED_WITH, {}, held_out, horizon_s),
    }
    return TuneReport(
        fit=result,
        train=[t.name for t in train],
        held_out=[t.name for t in held_out],
        held_out_samples=sum(len(t) for t in held_out),
        comparison=comparison,
    )
