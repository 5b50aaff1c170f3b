"""`rig bench predictors` (its command line declared in `rig.bench.predictors_settings`): what it measures.

Default traces:

* `pendulum`: the simulated rig's pendulum and tracker (120 Hz, 4 ms transport delay with jitter,
  0.2 mm and 0.05 deg noise), scored against the exact pendulum motion;
* `synthetic-head`: `predictors.synthetic.head_motion` at 120 Hz with 0.5 mm and 0.1 deg noise,
  scored against the clean motion;
* the two recordings in `data/traces/` (with their licences), each scored against itself:
  `hmd_orientation_user1` (orientation only, about 60 Hz with jitter) and `quest_pro_robot_traj2`
  (6-DoF, about 72 Hz).

`--corpus DIR` runs on a corpus of recordings instead, scored by recording and by person, scene and
device, and `--cross-validate` scores each group by the predictor chosen without it
(`rig.bench.corpus_bench`).

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

import argparse
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

import predictors
from predictors import Evaluation, Trace, read_trace
from predictors.cross_validation import CorpusScores
from predictors.stress import stress_streams
from predictors.synthetic import head_motion
from rig.bench import corpus_bench
from rig.bench.contract import Bench, Context
from rig.bench.corpus_bench import CorpusRun
from rig.bench.predictors_settings import BASELINE
from rig.bench.predictor_scores import (
    FailedEvaluation, HeldOut, cost_ratios, evaluate_all, label, leave_one_out, ratios_record, scores_of,
)
from rig.errors import ConfigError
from rig.service.tune import check_scorable, read_in_time_order
from rig.sim.pendulum import Pendulum, PendulumConfig
from rig.sim.tracker import TrackerConfig, measure

TRACES = Path(__file__).resolve().parents[2] / "data" / "traces"
RECORDINGS = (TRACES / "hmd_orientation_user1.csv", TRACES / "quest_pro_robot_traj2.csv")
_TRUTH_RATE_HZ = 1000.0


def pendulum_trace(duration_s: float, seed: int) -> Trace:
    """The simulated tracker on the default pendulum, with the exact motion as truth."""
    pendulum = Pendulum(PendulumConfig(), t_end=duration_s + 1.0)
    truth_t = np.arange(int(duration_s * _TRUTH_RATE_HZ) + 1) / _TRUTH_RATE_HZ
    truth = Trace.from_samples("pendulum", truth_t, *pendulum.sensor_pose(truth_t))
    samples = measure(pendulum, TrackerConfig(), 0.0, duration_s, seed).pose_samples()
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


def table(results: Sequence[Evaluation], horizons: Sequence[float]) -> str:
    """A Markdown table: per trace and predictor, us/update and RMS errors (mm, deg) per horizon."""
    head = "| trace | predictor | us/update | " + " | ".join(f"{h:g} ms: mm, deg" for h in horizons) + " |"
    rule = "|" + "---|" * (3 + len(horizons))
    rows = [head, rule]
    for result in results:
        cells = [f"{result.at(h).position_rms_mm:.3g}, {result.at(h).angular_rms_deg:.3g}" for h in horizons]
        rows.append(f"| {result.trace} | {label(result.predictor, result.params)} | {result.us_per_update:.1f} | " + " | ".join(cells) + " |")
    return "\n".join(rows)


def _has(scores: CorpusScores, part: str, trace: str | None = None) -> bool:
    """Whether any predictor's ratio of `part` is finite at any horizon on `trace` (None: on any it was scored on)."""
    return any(math.isfinite(scores.ratio(name, t, part, h)) for name, on in scores.evaluations.items()
               for t in on if trace in (None, t) for h in scores.horizons_ms)  # fmt: skip


def ratio_table(scores: CorpusScores, part: str, horizons: Sequence[float]) -> str:
    """A Markdown table of one part's ratios to constant velocity: per predictor, each trace's
    ratios at `horizons` (ms) joined by " / ", their geometric mean and worst, and the median cost.
    A predictor that failed on a trace has "failed" there, and its mean and worst say over how many
    of the traces they are."""
    traces = [t for t in scores.evaluations[scores.baseline] if _has(scores, part, t)]
    head = "| predictor | " + " | ".join(traces) + " | geometric mean | worst | us/update (median) |"
    rows = [head, "|" + "---|" * (len(traces) + 4)]
    for name, on in scores.evaluations.items():
        cells = [" / ".join(f"{scores.ratio(name, t, part, h):.3f}" for h in horizons) if t in on else "failed" for t in traces]
        ran = [t for t in traces if t in on]
        over_ran = "" if len(ran) == len(traces) else f" ({len(ran)} of {len(traces)} traces)"
        for over in (scores.group_ratio, scores.worst):
            cells.append(" / ".join(f"{over(name, ran, part, h):.3f}" for h in horizons) + over_ran)
        cost = float(np.median([evaluation.us_per_update for evaluation in on.values()]))
        rows.append(f"| {name} | " + " | ".join(cells) + f" | {cost:.1f} |")
    return "\n".join(rows)


def held_out_table(held: Sequence[HeldOut]) -> str:
    """A Markdown table of leave-one-trace-out ratios to constant velocity: tuned, and defaults."""
    rows = ["| predictor | held-out trace | horizon | tuned: angular, position | defaults: angular, position |", "|---|---|---|---|---|"]
    for h in held:
        if h.failed is not None:
            rows.append(f"| {h.predictor} | {h.trace} | {h.horizon_ms:g} ms | failed: {h.failed} | |")
            continue
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
    figure = Figure(figsize=(4.5 * max(len(traces), 1), 7.0))
    if not traces:
        figure.text(0.5, 0.5, "no predictor was scored on any trace: each failed (see the table)", ha="center")
        figure.savefig(path, dpi=100)
        return
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


@dataclass(frozen=True)
class Scores:
    """What the bench found: the horizons (ms) and the one plotted, every evaluation, the ratios to
    the baseline (on the traces where it was scored), kalman-cv's cost over desp's per trace, the
    leave-one-out results, and the evaluations that failed with their reasons."""

    horizons_ms: tuple[float, ...]
    plot_horizon_ms: float
    results: list[Evaluation]
    ratios: CorpusScores
    costs: dict[str, float]
    held: list[HeldOut]
    failed: list[FailedEvaluation]


def run(args: argparse.Namespace, context: Context) -> Scores | CorpusRun:
    """Every predictor named (all by default; the baseline always) on every trace (the files, the
    stress streams, or the default four), then each one named tuned with one trace held out in turn;
    or, with --corpus, the corpus bench (`rig.bench.corpus_bench`)."""
    horizons, plot_horizon = args.horizons_ms, args.plot_horizon_ms
    if plot_horizon not in horizons:
        raise ConfigError(f"--plot-horizon-ms {plot_horizon:g} must be one of --horizons-ms {','.join(f'{h:g}' for h in horizons)}")
    if args.corpus is None and (args.cross_validate or args.headroom or args.manifest is not None):
        raise ConfigError("--cross-validate, --headroom and --manifest need --corpus DIR: they group a corpus's recordings")
    if args.corpus is not None:
        if args.trace or args.stress or args.leave_one_out:
            raise ConfigError("--corpus runs on the corpus's recordings alone: leave out --trace, --stress and --leave-one-out")
        return corpus_bench.run(args, context)
    given, repaired = read_in_time_order(args.trace or [], args.repair)
    for note in repaired:
        context.log(f"repaired {note}")
    check_scorable(given, max(horizons) / 1e3)
    traces = given + (stress_streams(args.duration, args.seed) if args.stress else [])
    traces = traces or default_traces(args.duration, args.seed)
    if args.leave_one_out and len(traces) < 2:
        raise ConfigError("--leave-one-out needs at least two traces: it tunes on all but one")
    specs = args.predictor or [(name, {}) for name in predictors.names()]
    specs += [] if (BASELINE, {}) in specs else [(BASELINE, {})]
    for name, params in specs:
        predictors.make(name, **params)  # a parameter it does not take is refused before any work, not a failed row per trace
    failed: list[FailedEvaluation] = []
    results = evaluate_all(traces, specs, horizons, args.timing_repeats, context.progress("benchmarking predictors"), failed)
    for failure in failed:
        context.log(f"{failure.predictor} on {failure.trace} failed: {failure.failed}")
    scored = {r.trace for r in results if r.predictor == BASELINE and not r.params}
    held = [h for name in args.leave_one_out or () for h in leave_one_out(name, traces, plot_horizon, args.tune_iterations,
                                                                             context.progress(f"tuning {name}, each trace held out in turn"))]  # fmt: skip
    compared = scores_of([r for r in results if r.trace in scored], horizons)
    return Scores(horizons, plot_horizon, results, compared, cost_ratios(results), held, failed)


def every_evaluation_failed(scores: Scores | CorpusRun) -> str | None:
    """A sentence where no predictor was scored on any trace (each evaluation failed), else None."""
    if isinstance(scores, CorpusRun) or scores.results or not scores.failed:
        return None
    first = scores.failed[0]
    return f"every one of the {len(scores.failed)} evaluations failed (the first: {first.predictor} on {first.trace}: {first.failed})"


def text(scores: Scores | CorpusRun) -> str:
    """The scores table, the ratio tables (position where any trace has it), the costs and the held-out table."""
    if isinstance(scores, CorpusRun):
        return corpus_bench.text(scores)
    horizons = scores.horizons_ms
    shown = [h for h in horizons if h > 0.0] or list(horizons)
    at = " / ".join(f"{h:g}" for h in shown)
    lines = [table(scores.results, horizons)]
    lines += [f"| {f.trace} | {f.predictor} | failed: {f.failed} |" for f in scores.failed]
    if scores.ratios.candidates:
        lines += [f"\nangular RMS error / constant velocity ({BASELINE}) at {at} ms:", ratio_table(scores.ratios, "angular", shown)]
    if _has(scores.ratios, "position"):
        lines += [f"\nposition RMS error / constant velocity at {at} ms (traces with position):", ratio_table(scores.ratios, "position", shown)]
    lines += [f"kalman-cv / desp cost on {trace}: {ratio:.2f}" for trace, ratio in scores.costs.items()]
    if scores.held:
        lines += [f"\nleave one trace out: tuned at {scores.plot_horizon_ms:g} ms on the others, RMS error / constant velocity "
                  "on the one held out:", held_out_table(scores.held)]  # fmt: skip
    return "\n".join(lines)


def record(scores: Scores | CorpusRun) -> dict[str, Any]:
    """Every score, ratio and held-out result, as JSON-ready values."""
    if isinstance(scores, CorpusRun):
        return corpus_bench.record(scores)
    horizons = scores.horizons_ms
    return {
        "horizons_ms": list(horizons),
        "baseline": BASELINE,
        "kalman_cv_over_desp_cost": scores.costs,
        "ratios": ratios_record(scores.ratios),
        "leave_one_out": [h.to_dict() for h in scores.held],
        "results": [r.to_dict() for r in scores.results],
        "failed": [f.to_dict() for f in scores.failed],
    }


BENCH = Bench(
    run=run, table=text, record=record,
    plot=lambda scores, path: (corpus_bench.plot(scores, path) if isinstance(scores, CorpusRun)
                               else plot(scores.results, scores.plot_horizon_ms, path)),
    all_failed=every_evaluation_failed,
)
