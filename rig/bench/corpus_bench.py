"""The predictor bench on a corpus of recordings (`rig bench predictors --corpus DIR`): scores by
recording, by person, scene and device, and, with `--cross-validate`, each group scored by the
candidate chosen without it; with `--headroom`, how far a linear predictor on the default's
features, fitted on the other groups, goes on each group (`predictors.headroom`).

The recordings and their labels are `predictors.corpus`'s (file names or a manifest); the scores,
the choosing and the folds `predictors.cross_validation`'s. Every candidate is run on every
recording once, with constant velocity (`slerp`, the baseline) and `kalman-cv` (the cost
reference, timed in the same run) always among them. Recordings apart (a robot's) are scored and
listed but never grouped, chosen on or counted in a geometric mean.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from predictors import DEFAULT, names, resolve
from predictors.registry import params_of
from predictors.corpus import GROUPINGS, Recording, read_corpus
from predictors.cross_validation import REPORTED, CorpusScores, Fold, cross_validate, geometric_mean, groups_of, held_out_mean
from predictors.headroom import FITS, HeadroomFold, corpus_headroom, headroom
from rig.bench.contract import Context, new_figure
from rig.bench.predictor_scores import by_horizon, evaluate_all, scores_of
from rig.bench.predictors_settings import BASELINE
from rig.errors import ConfigError
from rig.service.tune import check_scorable, in_time_order

COST_REFERENCE = "kalman-cv"
# The candidates run when none is named: every predictor with its defaults, and those with a damped
# angular velocity at each rate a head's turn dies away at (1/s; see predictors.kalman) besides.
DAMPING_GRID = (2.0, 4.0, 8.0)
DAMPED = ("kalman-cv", "split")
_PLOTTED_ABOVE_BASELINE = 1.3  # the speed plot leaves out candidates this much worse than constant velocity


def default_candidates(names: Sequence[str]) -> list[tuple[str, dict[str, Any]]]:
    """Every predictor named with its defaults, then each of `DAMPED` at every other damping of `DAMPING_GRID`."""
    damped = [(name, {"angular_velocity_damping": d}) for name in DAMPED for d in DAMPING_GRID
              if d != params_of(name).resolve({})["angular_velocity_damping"]]  # fmt: skip
    return [*((name, {}) for name in names), *damped]


@dataclass(frozen=True)
class CorpusRun:
    """What the corpus bench found: the recordings, the scores, each candidate's cost over
    kalman-cv's (median over recordings), the folds per grouping (empty without
    --cross-validate), the default predictor's label, the horizon the plot shows, and the headroom
    folds per grouping (empty without --headroom)."""

    recordings: list[Recording]
    scores: CorpusScores
    costs: dict[str, float]
    folds: dict[str, list[Fold]]
    default: str
    plot_horizon_ms: float
    headroom: dict[str, list[HeadroomFold]]

    @property
    def shown(self) -> tuple[float, ...]:
        """The horizons reported (ms): those given, less 0."""
        return tuple(h for h in self.scores.horizons_ms if h > 0.0) or self.scores.horizons_ms

    def groups(self, by: str) -> dict[str, list[str]]:
        """Recording names by group under `by`."""
        return groups_of(self.recordings, by)


def run(args: argparse.Namespace, context: Context) -> CorpusRun:
    """Every candidate on every recording of the corpus, then the folds of each grouping."""
    recordings = []
    for recording in read_corpus(args.corpus, args.manifest):
        trace, repaired = in_time_order(recording.trace, args.repair)
        recordings.append(replace(recording, trace=trace))
        if repaired is not None:
            context.log(f"repaired {repaired}")
    check_scorable([r.trace for r in recordings], max(args.horizons_ms) / 1e3)
    specs = args.predictor or default_candidates(names())
    specs = [*(s for s in ((BASELINE, {}), (COST_REFERENCE, {})) if s not in specs), *specs]
    results = evaluate_all([r.trace for r in recordings], specs, args.horizons_ms, args.timing_repeats,
                           context.progress("benchmarking predictors on the corpus"))  # fmt: skip
    scores = scores_of(results, args.horizons_ms)
    evaluations = scores.evaluations
    costs = {name: float(np.median([by[r].us_per_update / evaluations[COST_REFERENCE][r].us_per_update for r in by]))
             for name, by in evaluations.items()}  # fmt: skip
    folds = {by: cross_validate(scores, groups_of(recordings, by)) for by in GROUPINGS} if args.cross_validate else {}
    folds = {by: f for by, f in folds.items() if len(f) > 1}
    traces = {r.name: r.trace for r in recordings}
    shown = [h for h in args.horizons_ms if h > 0.0]
    if args.headroom and not shown:
        raise ConfigError("--headroom fits predictions ahead: give a horizon above 0 in --horizons-ms")
    fitted = {by: headroom(traces, groups_of(recordings, by), shown) for by in GROUPINGS} if args.headroom else {}
    fitted = {by: f for by, f in fitted.items() if f}
    return CorpusRun(recordings, scores, costs, folds, resolve(DEFAULT), args.plot_horizon_ms, fitted)


def _cells(values: Sequence[float]) -> str:
    return " / ".join("-" if not math.isfinite(v) else f"{v:.3f}" for v in values)


def recording_table(found: CorpusRun) -> str:
    """Per recording: its labels, constant velocity's RMS and 95th-percentile angular error (deg)
    and RMS position error (mm) at each horizon, and each candidate's angular ratio at the plot horizon."""
    scores, h = found.scores, found.plot_horizon_ms
    head = ("| recording | device | person | scene | constant velocity: angular RMS, p95 (deg); position RMS (mm) at "
            + " / ".join(f"{x:g}" for x in found.shown) + " ms | " + " | ".join(scores.candidates) + " |")
    rows = [head, "|" + "---|" * (5 + len(scores.candidates))]
    for r in found.recordings:
        base = [scores.evaluations[BASELINE][r.name].at(x) for x in found.shown]
        cv = "; ".join(f"{b.angular_rms_deg:.2f}, {b.angular_p95_deg:.2f}; {b.position_rms_mm:.1f}" for b in base)
        ratios = [f"{scores.ratio(c, r.name, 'angular', h):.3f}" for c in scores.candidates]
        person = f"{r.person} (apart)" if r.apart else r.person
        rows.append(f"| {r.name} | {r.device} | {person} | {r.scene or '-'} | {cv} | " + " | ".join(ratios) + " |")
    return "\n".join(rows)


def candidate_table(found: CorpusRun, by: str) -> str:
    """Per candidate, over the groups under `by`: the geometric mean of angular RMS, angular p95 and
    position RMS ratios per horizon, the worst recording's angular ratio, and the cost."""
    scores, groups = found.scores, found.groups(by)
    names = [r for members in groups.values() for r in members]
    rows = [f"| candidate | angular RMS | angular p95 | position RMS | worst recording, angular | cost / {COST_REFERENCE} |",
            "|---|---|---|---|---|---|"]  # fmt: skip
    for c in scores.candidates:
        cells = [_cells([scores.corpus_ratio(c, groups, part, h) for h in found.shown]) for part in ("angular", "angular_p95", "position")]
        worst = _cells([scores.worst(c, names, "angular", h) for h in found.shown])
        rows.append(f"| {c} | " + " | ".join(cells) + f" | {worst} | {found.costs[c]:.2f} |")
    return "\n".join(rows)


def fold_table(found: CorpusRun, by: str) -> str:
    """Per group held out: the candidate chosen on the others, its ratios there (angular RMS and
    p95, position RMS, worst recording), and the default's and kalman-cv's angular ratios beside."""
    scores, at = found.scores, " / ".join(f"{h:g}" for h in found.shown)
    rows = [f"| held out ({by}) | recordings | chosen on the others | angular RMS | angular p95 | position RMS | worst recording, "
            f"angular | {found.default}, angular | {COST_REFERENCE}, angular |", "|" + "---|" * 9]  # fmt: skip
    for fold in found.folds[by]:
        cells = [_cells([fold.ratios[part][h] for h in found.shown]) for part in ("angular", "angular_p95", "position")]
        fixed = [_cells([scores.group_ratio(c, fold.recordings, "angular", h) for h in found.shown])
                 if c in scores.evaluations else "-" for c in (found.default, COST_REFERENCE)]  # fmt: skip
        rows.append(f"| {fold.group} | {len(fold.recordings)} | {fold.chosen} | " + " | ".join(cells) + " | "
                    + _cells([fold.worst["angular"][h] for h in found.shown]) + " | " + " | ".join(fixed) + " |")
    means = [_cells([held_out_mean(found.folds[by], part, h) for h in found.shown]) for part in ("angular", "angular_p95", "position")]
    rows.append(f"| geometric mean over groups | | | " + " | ".join(means) + " | | | |")
    return f"(ratios to constant velocity at {at} ms)\n" + "\n".join(rows)


def headroom_table(found: CorpusRun, by: str) -> str:
    """Per group held out: each linear fit's ratios there, made on the other groups, and the
    default's, learnt on the stream; their geometric means over groups last."""
    folds, shown, scores = found.headroom[by], found.shown, found.scores
    on_stream = [[scores.group_ratio(found.default, f.recordings, "angular", h) for h in shown] if found.default in scores.evaluations
                 else [math.nan] * len(shown) for f in folds]  # fmt: skip
    rows = [f"| held out ({by}) | recordings | " + " | ".join(f"{fit}, fitted on the others" for fit in FITS)
            + f" | {found.default}, on the stream |", "|" + "---|" * (3 + len(FITS))]  # fmt: skip
    for fold, default in zip(folds, on_stream):
        rows.append(f"| {fold.group} | {len(fold.recordings)} | " + " | ".join(_cells([fold.ratios[fit][h] for h in shown]) for fit in FITS)
                    + f" | {_cells(default)} |")  # fmt: skip
    means = [_cells([corpus_headroom(folds, fit, h) for h in shown]) for fit in FITS]
    default_mean = _cells([geometric_mean([row[k] for row in on_stream]) for k in range(len(shown))])
    rows.append("| geometric mean over groups | | " + " | ".join(means) + f" | {default_mean} |")
    return "\n".join(rows)


def text(found: CorpusRun) -> str:
    """The recording table, the candidates by person, each grouping's folds with its
    cross-validated geometric mean, and each grouping's headroom."""
    at = " / ".join(f"{h:g}" for h in found.shown)
    lines = [recording_table(found),
             f"\nby person (geometric mean over people; ratios to constant velocity at {at} ms), chosen on all of them: "
             f"{found.scores.choose(found.groups('person'))}", candidate_table(found, "person")]  # fmt: skip
    for by, folds in found.folds.items():
        lines += [f"\nleave one {by} out: chosen on the others, scored on the one held out", fold_table(found, by)]
        lines.append(f"cross-validated ({by}): angular RMS / constant velocity at {at} ms: "
                     + _cells([held_out_mean(folds, "angular", h) for h in found.shown]))  # fmt: skip
    at = " / ".join(f"{h:g}" for h in found.shown)
    for by in found.headroom:
        lines += [f"\nheadroom, leave one {by} out: linear predictors on {found.default}'s features fitted with every future "
                  f"sample known on the other groups (shared: one coefficient per feature; yaw/tilt: one along each "
                  f"recording's principal axis of turning, one across it; per axis: a matrix in the world frame), angular RMS / "
                  f"constant velocity at {at} ms on the one held out", headroom_table(found, by)]  # fmt: skip
    return "\n".join(lines)


def _ratios(found: CorpusRun, candidate: str, recordings: Sequence[str]) -> dict[str, dict[str, float | None]]:
    """The candidate's ratios over the recordings (their geometric mean) per reported part and horizon."""
    return {part: by_horizon(partial(found.scores.group_ratio, candidate, recordings, part), found.shown)
            for part in REPORTED}  # fmt: skip


def record(found: CorpusRun) -> dict[str, Any]:
    """Labels, every evaluation, each candidate's ratios per recording and group, the folds and
    the cross-validated means, as JSON-ready values."""
    scores = found.scores
    groupings = {by: found.groups(by) for by in GROUPINGS}
    return {
        "horizons_ms": list(found.shown),
        "baseline": BASELINE,
        "cost_reference": COST_REFERENCE,
        "default": found.default,
        "recordings": [{"name": r.name, "device": r.device, "person": r.person, "scene": r.scene, "apart": r.apart} for r in found.recordings],
        "candidates": {
            c: {
                "cost_over_kalman_cv": found.costs[c],
                "recordings": {r.name: _ratios(found, c, [r.name]) for r in found.recordings},
                "groups": {by: {g: _ratios(found, c, members) for g, members in groups.items()} for by, groups in groupings.items()},
                "geometric_mean": {by: {part: by_horizon(partial(scores.corpus_ratio, c, groups, part), found.shown)
                                        for part in REPORTED} for by, groups in groupings.items()},  # fmt: skip
            }
            for c in scores.candidates
        },
        "cross_validation": {
            by: {
                "folds": [{"group": f.group, "recordings": list(f.recordings), "chosen": f.chosen,
                           "ratios": _ratios(found, f.chosen, f.recordings)} for f in folds],  # fmt: skip
                "geometric_mean": {part: by_horizon(partial(held_out_mean, folds, part), found.shown) for part in REPORTED},
            }
            for by, folds in found.folds.items()
        },
        "headroom": {
            by: {
                "folds": [{"group": f.group, "recordings": list(f.recordings),
                           "ratios": {fit: by_horizon(f.ratios[fit].__getitem__, found.shown) for fit in FITS}} for f in folds],  # fmt: skip
                "geometric_mean": {fit: by_horizon(partial(corpus_headroom, folds, fit), found.shown) for fit in FITS},
            }
            for by, folds in found.headroom.items()
        },
        "results": [e.to_dict() for by in scores.evaluations.values() for e in by.values()],
    }


def plot(found: CorpusRun, path: Path) -> None:
    """Left: each candidate's geometric mean over people of angular RMS / constant velocity at the
    plot horizon against its cost over kalman-cv's. Right: per person held out, the chosen
    candidate's angular ratio at each horizon (or, without folds, the default's), and with
    --headroom the linear fits made on the other people, at the plot horizon."""
    figure, (left, right) = new_figure((13.0, 5.0), nrows=1, ncols=2)
    scores, groups, h = found.scores, found.groups("person"), found.plot_horizon_ms
    ratios = {c: scores.corpus_ratio(c, groups, "angular", h) for c in scores.candidates}
    shown = {c: r for c, r in ratios.items() if r <= _PLOTTED_ABOVE_BASELINE}
    for c, ratio in shown.items():
        left.scatter(found.costs[c], ratio)
        left.annotate(c, (found.costs[c], ratio), textcoords="offset points", xytext=(4, 4), fontsize="small")
    left.axhline(1.0, color="grey", linewidth=0.8)
    hidden = ", ".join(c for c in ratios if c not in shown)
    left.set(xlabel=f"cost per update + predict / {COST_REFERENCE}'s", ylabel=f"angular RMS / constant velocity at {h:g} ms",
             title="geometric mean over people" + (f" (above {_PLOTTED_ABOVE_BASELINE:g}: {hidden})" if hidden else ""))  # fmt: skip
    folds = found.folds.get("person")
    names = [f.group for f in folds] if folds else list(groups)
    width = 0.8 / len(found.shown)
    heights: list[float] = []
    for k, horizon in enumerate(found.shown):
        values = ([f.ratios["angular"][horizon] for f in folds] if folds
                  else [scores.group_ratio(found.default, groups[g], "angular", horizon) for g in names])  # fmt: skip
        right.bar(np.arange(len(names)) + k * width, values, width, label=f"{horizon:g} ms")
        heights += values
    fitted = {f.group: f for f in found.headroom.get("person", [])}
    if fitted and h in found.shown:
        at = np.arange(len(names)) + found.shown.index(h) * width
        for fit, marker in zip(FITS, ("_", "+", "x")):
            values = [fitted[g].ratios[fit][h] if g in fitted else math.nan for g in names]
            right.scatter(at, values, marker=marker, s=120, color="black", zorder=3, label=f"{fit} linear fit, {h:g} ms")
            heights += values
    right.axhline(1.0, color="grey", linewidth=0.8)
    heights = [v for v in heights if math.isfinite(v)]
    right.set_ylim(0.95 * min([*heights, 1.0]), 1.02 * max([*heights, 1.0]))
    right.set_xticks(np.arange(len(names)) + 0.4 - width / 2, names, rotation=60, ha="right", fontsize="small")
    right.set(ylabel="angular RMS / constant velocity",
              title="held out: chosen on the other people" if folds else f"{found.default} per person")  # fmt: skip
    right.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.0, 1.0))
    figure.tight_layout()
    figure.savefig(path, dpi=100)
