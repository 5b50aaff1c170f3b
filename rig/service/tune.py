"""Fit a predictor's parameters to recorded motion, check them on motion held out, and keep them only
if they do better there than the defaults.

Each trace is split in time: its first part (`split` of its duration) to train on, the rest to
validate on; or the validation traces are given. The fitted parameters, the predictor's defaults
(with any parameter the user fixed), constant velocity (`slerp`) and the default predictor are
each scored on both parts. The tuned parameters *lose* when their validation error, relative to
the defaults' (the mean over orientation and, where the traces move, position of the ratio of
mean squared errors: the tuning loss), is above 1; the command then writes nothing unless forced.

The parameter file is what `rig simulate --predictor NAME:FILE.json`, `rig bench predictors
--predictor NAME:FILE.json` and `predictors.make(name, **predictors.read_params(FILE)[1])` accept.

Traces must be in time order without a repeated time: a recording whose clock went back or logged
a time twice is refused with the first place it happened, or put in order (`repair`): sorted by
time, a repeated time kept once (its last sample).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Sequence

import numpy as np

from predictors import DEFAULT, Trace, evaluate, read_trace, resolve, write_params
from rig import interrupts
from rig.errors import ConfigError

if TYPE_CHECKING:
    from predictors.tuning import TuneResult

COMPARED_WITH = "slerp"
"""The baseline: constant velocity from the last two samples."""

PARTS = ("training", "validation")


MIN_SAMPLES = 10
"""The fewest samples a trace (or a part of one) is scored on: fewer give an error of no meaning."""


def in_time_order(trace: Trace, repair: bool) -> tuple[Trace, str | None]:
    """The trace, or with `repair` its samples in time order (and what was repaired); ConfigError
    naming the first fault otherwise."""
    backward, repeated = trace.order_faults()
    if not backward and not repeated:
        return trace, None
    steps = np.diff(trace.t)
    first = int(np.argmax(steps <= 0.0)) + 1
    what = f"{backward} sample(s) earlier than the one before and {repeated} at the same time as the one before"
    if not repair:
        raise ConfigError(
            f"trace {trace.name!r} is not in time order: {what} (first: sample {first}, t={trace.t[first]:.9g} s after "
            f"{trace.t[first - 1]:.9g} s); sort it by time and drop repeated times, or pass --repair"
        )
    repaired = trace.in_time_order()
    return repaired, f"{trace.name}: {what}; sorted by time, {len(trace) - len(repaired)} repeated time(s) dropped"


def read_in_time_order(paths: Sequence[Path], repair: bool) -> tuple[list[Trace], list[str]]:
    """The trace files, each `in_time_order`, and what was repaired in them."""
    traces, repaired = [], []
    for path in paths:
        trace, note = in_time_order(read_trace(path), repair)
        traces.append(trace)
        if note is not None:
            repaired.append(note)
    return traces, repaired


def check_scorable(traces: Sequence[Trace], horizon_s: float) -> None:
    """ConfigError naming the first trace too short to score a prediction `horizon_s` ahead: fewer
    than MIN_SAMPLES samples, or no longer than the horizon (no prediction would land on its truth)."""
    for trace in traces:
        if len(trace) < MIN_SAMPLES or not trace.duration > horizon_s:
            raise ConfigError(
                f"trace {trace.name!r} has {len(trace)} sample(s) over {trace.duration:.6g} s: scoring a prediction "
                f"{horizon_s * 1e3:g} ms ahead needs at least {MIN_SAMPLES} samples over more than {horizon_s * 1e3:g} ms; "
                "record longer (or, tuning, give a larger --split or a --held-out trace)"
            )


def split_traces(traces: Sequence[Trace], held_out: Sequence[Trace], split: float) -> tuple[list[Trace], list[Trace]]:
    """(training, validation): the given held-out traces, else the end of each training trace."""
    if held_out:
        return list(traces), list(held_out)
    halves = [trace.split(split) for trace in traces]
    return [h[0] for h in halves], [h[1] for h in halves]


def rms_errors(name: str, params: dict[str, Any], traces: Sequence[Trace], horizon_s: float) -> dict[str, float]:
    """Angular (deg) and position (mm) RMS error over the traces, weighted by count."""
    scores = [evaluate(name, trace, [horizon_s], params, timing_repeats=0).scores[0] for trace in traces]
    count = sum(s.count for s in scores)
    angular = (sum(s.count * s.angular_rms_deg**2 for s in scores) / count) ** 0.5
    position = (sum(s.count * s.position_rms_mm**2 for s in scores) / count) ** 0.5
    return {"angular_rms_deg": angular, "position_rms_mm": position}


def relative_loss(errors: dict[str, float], reference: dict[str, float]) -> float:
    """The tuning loss of `errors` over `reference`'s: the mean ratio of mean squared errors over the
    parts the reference has any error in (1 where it has none)."""
    ratios = [(errors[k] / reference[k]) ** 2 for k in ("angular_rms_deg", "position_rms_mm") if reference[k] > 0.0]
    return sum(ratios) / len(ratios) if ratios else 1.0


@dataclass(frozen=True)
class TuneReport:
    """The fit, and the RMS errors on training and validation of the tuned parameters, the
    defaults, constant velocity and the default predictor: `errors[part][label]` holds
    `{"angular_rms_deg", "position_rms_mm"}`; `validation_loss` is the tuned parameters' relative to
    the defaults' on validation (below 1 is better)."""

    fit: TuneResult
    horizon_ms: float
    labels: dict[str, str]
    samples: dict[str, int]
    traces: dict[str, list[str]]
    errors: dict[str, dict[str, dict[str, float]]]
    validation_loss: float
    repaired: list[str] = field(default_factory=list)

    @property
    def beats_defaults(self) -> bool:
        """Whether the tuned parameters predict the validation part at least as well as the defaults."""
        return self.validation_loss <= 1.0

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-ready values."""
        fit = self.fit
        return {
            "predictor": fit.predictor,
            "horizon_ms": self.horizon_ms,
            "labels": self.labels,
            "params": fit.params,
            "fitted": list(fit.fitted),
            "training_loss": {"before": fit.loss_before, "after": fit.loss_after, "iterations": fit.iterations},
            "samples": self.samples,
            "traces": self.traces,
            "errors": self.errors,
            "validation_loss_over_defaults": self.validation_loss,
            "beats_defaults": self.beats_defaults,
            "repaired": self.repaired,
        }

    def write(self, path: Path) -> None:
        """The parameter file, with what it was fitted on and how well it did."""
        fit = self.fit
        write_params(
            path, fit.predictor, fit.params, horizon_ms=self.horizon_ms, fitted=list(fit.fitted),
            traces=self.traces, errors=self.errors, validation_loss_over_defaults=self.validation_loss,
        )


def tune(
    name: str,
    start: dict[str, Any],
    train: Sequence[Trace],
    validation: Sequence[Trace],
    horizon_s: float,
    max_iterations: int,
    progress: Callable[[float, float], object] | None = None,
    repaired: Sequence[str] = (),
) -> TuneReport:
    """Fit `name` from `start` on `train` at `horizon_s` and score it, its starting parameters, the
    baseline and the default predictor on both parts; `progress(done, total)` follows the fit and
    the scoring."""
    with interrupts.deferred():  # an interrupt inside jaxlib's extension init would abort the process
        from predictors.tuning import tune as fit  # imports JAX: only when tuning

    scoring_steps = len(PARTS) * 4
    fit_steps = [max_iterations]

    def fitting(done: float, total: float) -> None:
        fit_steps[0] = int(total)
        if progress is not None:
            progress(done, total + scoring_steps)

    result = fit(name, list(train), horizon_s, start, max_iterations=max_iterations, progress=fitting)
    labels = {
        "tuned": f"{name} tuned",
        "defaults": f"{name} defaults",
        "baseline": f"{COMPARED_WITH} (constant velocity)",
        "default": f"{DEFAULT} ({resolve(DEFAULT)})",
    }
    specs = {"tuned": (name, result.params), "defaults": (name, start), "baseline": (COMPARED_WITH, {}), "default": (DEFAULT, {})}
    errors: dict[str, dict[str, dict[str, float]]] = {}
    for part, traces in zip(PARTS, (train, validation)):
        errors[part] = {}
        for key, (predictor, params) in specs.items():
            errors[part][key] = rms_errors(predictor, params, traces, horizon_s)
            if progress is not None:
                progress(fit_steps[0] + len(errors) * len(specs) - len(specs) + len(errors[part]), fit_steps[0] + scoring_steps)
    return TuneReport(
        fit=result,
        horizon_ms=1e3 * horizon_s,
        labels=labels,
        samples={"training": sum(len(t) for t in train), "validation": sum(len(t) for t in validation)},
        traces={"training": [t.name for t in train], "validation": [t.name for t in validation]},
        errors=errors,
        validation_loss=relative_loss(errors["validation"]["tuned"], errors["validation"]["defaults"]),
        repaired=list(repaired),
    )
