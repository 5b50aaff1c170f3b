"""The predictor bench (`rig bench predictors`): every predictor on every trace, its error against
constant velocity and against its cost.

Default traces:

* `pendulum`: the simulated rig's pendulum and tracker (120 Hz, 4 ms transport delay with jitter,
  0.2 mm and 0.05 deg noise), scored against the exact pendulum motion;
* `synthetic-head`: `predictors.synthetic.head_motion` at 120 Hz with 0.5 mm and 0.1 deg noise,
  scored against the clean motion;
* the two recordings in `data/traces/` (with their licences), each scored against itself:
  `hmd_orientation_user1` (orientation only, about 60 Hz with jitter) and `quest_pro_robot_traj2`
  (6-DoF, about 72 Hz).

`--stress` runs the stress streams of `predictors.stress` instead (30 to 1000 Hz, clean to noisy,
jittered, repeated samples, coloured noise, sudden stops), `--trace` files as well or instead.

Horizons count from each sample's arrival at the host. Per predictor and trace: RMS errors per
horizon and microseconds per update plus one predict; the ratio of its RMS error to that of
constant velocity from the last two samples (`slerp`), angular and, where the trace moves,
positional; and the geometric mean of each ratio across the traces. Predictors named with
`--leave-one-out` are tuned (`predictors.tuning`) at the headline horizon on every trace but one
and scored on that one, for each trace in turn: the score of a tuned predictor on motion it was
not tuned on. Writes JSON and a PNG of speed against error if asked.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from predictors import Evaluation, Trace, evaluate, read_trace
from predictors.stress import stress_streams
from predictors.synthetic import head_motion
from rig.sim.pendulum import Pendulum, PendulumConfig
from rig.sim.tracker import TrackerConfig, simulate_tracker

TRACES = Path(__file__).resolve().parents[2] / "data" / "traces"
RECORDINGS = (TRACES / "hmd_orientation_user1.csv", TRACES / "quest_pro_robot_traj2.csv")
DEFAULT_HORIZONS_MS = (0.0, 10.0, 20.0, 50.0, 100.0)
BASELINE = "slerp"
_TRUTH_RATE_HZ = 1000.0


def pendulum_trace(duration_s: float, seed: int) -> Trace:
    """The simulated tracker on the default pendulum, with the exact motion as truth."""
    pendulum = Pendulum(PendulumConfig(), t_end=duration_s + 1.0)
    truth_t = np.arange(int(duration_s * _TRUTH_RATE_HZ) + 1) / _TRUTH_RATE_HZ
    truth = Trace.from_samples("pendulum", truth_t, *pendulum.sensor_pose(truth_t))
    samples = simulate_tracker(pendulum, TrackerConfig(), 0.0, duration_s, seed)
    return truth.with_samples(
        np.array([s.t_sensor for s in samples]),
        np.array([s.t_arrival for s in samples]),
        np.array([s.position for s in samples]),
        np.array([s.orientation for s in samples]),
    )


def default_traces(duration_s: float, seed: int) -> list[Trace]:
    """The pendulum, the synthetic head and the two recordings."""
    head = head_motion(duration_s, 120.0, seed).with_noise(0.0005, math.radians(0.1), seed)
    return [pendulum_trace(duration_s, seed), head, *(read_trace(path) for path in RECORDINGS)]


def stress_traces(duration_s: float, seed: int) -> list[Trace]:
    """The stress streams (`predictors.stress.stress_streams`)."""
    return stress_streams(duration_s, seed)


def label(name: str, params: dict[str, Any]) -> str:
    """A predictor spec as one word: its name, and its parameters where any were given."""
    return name if not params else f"{name}:" + ",".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in params.items())


def run_bench(
    traces: Sequence[Trace],
    specs: Sequence[tuple[str, dict[str, Any]]],
    horizons: Sequence[float],
    timing_repeats: int,
    progress: Callable[[float, float], object] | None = None,
) -> list[Evaluation]:
    """Every predictor spec on every trace."""
    results = []
    total = len(traces) * len(specs)
    for i, trace in enumerate(traces):
        for j, (name, params) in enumerate(specs):
            results.append(evaluate(name, trace, [h / 1e3 for h in horizons], params, timing_repeats))
            if progress is not None:
                progress(i * len(specs) + j + 1, total)
    return results


@dataclass(frozen=True)
class Ratios:
    """One predictor's RMS errors over constant velocity's on each trace, per horizon (ms): angular,
    and positional (NaN where constant velocity's position error is zero: no position to predict)."""

    predictor: str
    angular: dict[str, dict[float, float]]
    position: dict[str, dict[float, float]]
    us_per_update: dict[str, float]

    def geometric_mean(self, part: str, horizon_ms: float) -> float:
        """The geometric mean of one part's ratios across the traces that have it (NaN if none)."""
        values = [by_horizon[horizon_ms] for by_horizon in getattr(self, part).values()]
        values = [v for v in values if math.isfinite(v) and v > 0.0]
        return math.exp(sum(math.log(v) for v in values) / len(values)) if values else math.nan

    def worst(self, part: str, horizon_ms: float) -> float:
        """The largest ratio of one part across the traces (NaN if none)."""
        values = [by_horizon[horizon_ms] for by_horizon in getattr(self, part).values()]
        values = [v for v in values if math.isfinite(v)]
        return max(values) if values else math.nan

    def to_dict(self, horizons: Sequence[float]) -> dict[str, Any]:
        """Plain JSON-ready values, the geometric means and worst ratios per horizon included."""
        return {
            "predictor": self.predictor,
            "angular": _keyed(self.angular),
            "position": _keyed(self.position),
            "us_per_update": self.us_per_update,
            "geometric_mean": {part: {f"{h:g}": _finite(self.geometric_mean(part, h)) for h in horizons} for part in ("angular", "position")},
            "worst": {part: {f"{h:g}": _finite(self.worst(part, h)) for h in horizons} for part in ("angular", "position")},
        }


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _keyed(ratios: dict[str, dict[float, float]]) -> dict[str, dict[str, float | None]]:
    return {trace: {f"{h:g}": _finite(v) for h, v in by_horizon.items()} for trace, by_horizon in ratios.items()}


def ratios(results: Sequence[Evaluation], horizons: Sequence[float]) -> list[Ratios]:
    """Every predictor's ratios to the baseline (`BASELINE`, which must be among the results)."""
    baseline = {r.trace: r for r in results if r.predictor == BASELINE and not r.params}
    missing = sorted({r.trace for r in results} - set(baseline))
    if missing:
        raise ValueError(f"ratios need {BASELINE} with its defaults on every trace; missing on {', '.join(missing)}")
    by_label: dict[str, Ratios] = {}
    for result in results:
        entry = by_label.setdefault(label(result.predictor, result.params), Ratios(label(result.predictor, result.params), {}, {}, {}))
        base = baseline[result.trace]
        entry.angular[result.trace] = {h: _ratio(result.at(h).angular_rms_deg, base.at(h).angular_rms_deg) for h in horizons}
        entry.position[result.trace] = {h: _ratio(result.at(h).position_rms_mm, base.at(h).position_rms_mm) for h in horizons}
        entry.us_per_update[result.trace] = result.us_per_update
    return list(by_label.values())


def _ratio(error: float, baseline: float) -> float:
    return error / baseline if baseline > 0.0 else math.nan


def table(results: Sequence[Evaluation], horizons: Sequence[float]) -> str:
    """A Markdown table: per trace and predictor, us/update and RMS errors (mm, deg) per horizon."""
    head = "| trace | predictor | us/update | " + " | ".join(f"{h:g} ms: mm, deg" for h in horizons) + " |"
    rule = "|" + "---|" * (3 + len(horizons))
    rows = [head, rule]
    for result in results:
        cells = [f"{result.at(h).position_rms_mm:.3g}, {result.at(h).angular_rms_deg:.3g}" for h in horizons]
        rows.append(f"| {result.trace} | {label(result.predictor, result.params)} | {result.us_per_update:.1f} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def ratio_table(entries: Sequence[Ratios], part: str, horizons: Sequence[float]) -> str:
    """A Markdown table of one part's ratios to constant velocity: per predictor, each trace's
    ratios at `horizons` (ms) joined by " / ", their geometric mean and worst, and the median cost."""
    traces = [t for t in entries[0].angular if any(math.isfinite(v) for e in entries for v in getattr(e, part)[t].values())]
    head = "| predictor | " + " | ".join(traces) + " | geometric mean | worst | us/update (median) |"
    rows = [head, "|" + "---|" * (len(traces) + 4)]
    for entry in entries:
        cells = [" / ".join(f"{getattr(entry, part)[t][h]:.3f}" for h in horizons) for t in traces]
        summary = [" / ".join(f"{entry.geometric_mean(part, h):.3f}" for h in horizons), " / ".join(f"{entry.worst(part, h):.3f}" for h in horizons)]
        rows.append(f"| {entry.predictor} | " + " | ".join(cells + summary) + f" | {float(np.median(list(entry.us_per_update.values()))):.1f} |")
    return "\n".join(rows)


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
    and position RMS error there over constant velocity's, and its defaults' ratios beside them."""

    predictor: str
    trace: str
    horizon_ms: float
    params: dict[str, Any]
    angular: float
    position: float
    defaults_angular: float
    defaults_position: float

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-ready values (None for a ratio on a trace without that part)."""
        return {k: _finite(v) if isinstance(v, float) else v for k, v in vars(self).items()}


def leave_one_out(
    name: str, traces: Sequence[Trace], horizon_ms: float, max_iterations: int,
    progress: Callable[[float, float], object] | None = None,
) -> list[HeldOut]:
    """Tune `name` on all traces but one and score it on that one, for each trace in turn."""
    from predictors.tuning import tune  # imports JAX: only when asked

    horizon = horizon_ms / 1e3
    held = []
    for k, trace in enumerate(traces):
        others = [t for i, t in enumerate(traces) if i != k]
        params = tune(name, others, horizon, max_iterations=max_iterations).params
        scores = {
            key: evaluate(predictor, trace, [horizon], given, timing_repeats=0).scores[0]
            for key, predictor, given in (("tuned", name, params), ("defaults", name, {}), ("baseline", BASELINE, {}))
        }
        base = scores["baseline"]
        held.append(HeldOut(
            name, trace.name, horizon_ms, params,
            _ratio(scores["tuned"].angular_rms_deg, base.angular_rms_deg),
            _ratio(scores["tuned"].position_rms_mm, base.position_rms_mm),
            _ratio(scores["defaults"].angular_rms_deg, base.angular_rms_deg),
            _ratio(scores["defaults"].position_rms_mm, base.position_rms_mm),
        ))
        if progress is not None:
            progress(k + 1, len(traces))
    return held


def held_out_table(held: Sequence[HeldOut]) -> str:
    """A Markdown table of leave-one-trace-out ratios to constant velocity: tuned, and defaults."""
    rows = ["| predictor | held-out trace | horizon | tuned: angular, position | defaults: angular, position |", "|---|---|---|---|---|"]
    for h in held:
        rows.append(
            f"| {h.predictor} | {h.trace} | {h.horizon_ms:g} ms | {h.angular:.3f}, {h.position:.3f} | "
            f"{h.defaults_angular:.3f}, {h.defaults_position:.3f} |"
        )
    return "\n".join(rows).replace("nan", "-")


def plot(results: Sequence[Evaluation], horizon_ms: float, path: Path) -> None:
    """Speed against error at one horizon: one column per trace, angle above, position below.

    A trace without position (every predictor's position error zero) gets no position panel.
    """
    from matplotlib.figure import Figure

    traces = list(dict.fromkeys(r.trace for r in results))
    figure = Figure(figsize=(4.5 * len(traces), 7.0))
    axes = figure.subplots(2, len(traces), squeeze=False)
    for column, trace in enumerate(traces):
        of_trace = [r for r in results if r.trace == trace]
        for row, (field, unit) in enumerate((("angular_rms_deg", "deg"), ("position_rms_mm", "mm"))):
            axis = axes[row][column]
            if all(getattr(r.at(horizon_ms), field) == 0.0 for r in of_trace):
                axis.set_axis_off()
                axis.text(0.5, 0.5, f"{trace}: no {'position' if unit == 'mm' else 'orientation'} data", ha="center", transform=axis.transAxes)
                continue
            for result in of_trace:
                error = getattr(result.at(horizon_ms), field)
                axis.scatter(result.us_per_update, error)
                axis.annotate(label(result.predictor, result.params), (result.us_per_update, error), textcoords="offset points", xytext=(4, 4))
            axis.set_xlabel("us per update + predict")
            axis.set_ylabel(f"RMS error at {horizon_ms:g} ms ({unit})")
            axis.set_title(trace if row == 0 else "")
            axis.grid(True, alpha=0.3)
    figure.tight_layout()
    figure.savefig(path, dpi=100)
